#include "scoleid/identify/run/fit_plot.h"

#include <algorithm>
#include <complex>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "scoleid/io/error.h"
#include "scoleid/io/process.h"

namespace scoleid::identify {

std::string gnuplot_quote(const std::string& text) {
  std::string q = "'";
  for (char c : text) {
    if (c == '\'') q += "''";
    else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) q += ' ';
    else q += c;
  }
  return q + "'";
}

std::string fit_plot_script(const std::vector<std::string>& sensors, const std::vector<std::pair<int, double>>& cost,
                            const std::string& csv, const std::string& png, const FitPlotAnnotations& notes,
                            int binary_columns) {
  const std::size_t ns = sensors.size();
  // How each curve reads the table: past the CSV's header line, or as raw rows of float64.
  const std::string layout =
      binary_columns > 0 ? " binary format='%" + std::to_string(binary_columns) + "float64' using 1:" : " every ::1 using 1:";
  const bool zoom = notes.zoom_to > notes.zoom_from;
  const std::size_t cols = zoom ? 2 : 1;
  const std::string data = gnuplot_quote(csv);
  std::string gp = "set terminal pngcairo size " + std::to_string(zoom ? 1600 : 1000) + "," + std::to_string(300 * (ns + 1) + 40) +
                   " noenhanced\nset output " + gnuplot_quote(png) + "\nset datafile separator ','\nset multiplot layout " +
                   std::to_string(ns + 1) + "," + std::to_string(cols) +
                   (notes.title.empty() ? std::string() : " title " + gnuplot_quote(notes.title)) + "\nset grid\nset key top right\n";
  auto panel = [&](std::size_t k, bool window) {
    const std::size_t c = 2 + 3 * k;
    const std::string unit = k < notes.units.size() && !notes.units[k].empty() ? " [" + notes.units[k] + "]" : "";
    gp += "set title " + gnuplot_quote(sensors[k] + (window ? " (window)" : "")) + "\nset xlabel 't [s]'\nset ylabel " +
          gnuplot_quote(sensors[k] + unit) + "\nset y2tics\nset ytics nomirror\n";
    gp += window ? "set xrange [" + io::format_value(notes.zoom_from) + ":" + io::format_value(notes.zoom_to) + "]\n"
                 : "set autoscale x\n";
    gp += "plot " + data + layout + std::to_string(c) + " with lines lw 2 title 'measured', ''" + layout +
          std::to_string(c + 1) + " with lines dt 2 lw 2 title 'predicted', ''" + layout + std::to_string(c + 2) +
          " axes x1y2 with lines lc rgb 'gray' title 'residual (right axis)'\n";
  };
  for (std::size_t k = 0; k < ns; ++k) {
    panel(k, false);
    if (zoom) panel(k, true);
  }
  gp += "set autoscale x\nunset y2tics\nset ytics mirror\nset title 'cost per iteration'\nset xlabel 'iteration'\n"
        "set ylabel 'J'\nset logscale y\nplot '-' using 1:2 with linespoints lw 2 notitle\n";
  for (const auto& [k, c] : cost) gp += std::to_string(k) + "," + io::format_value(c) + "\n";
  gp += "e\nunset multiplot\n";
  return gp;
}

SpectrumView spectrum_view(const std::vector<double>& f, const Eigen::MatrixXd& measured, const Eigen::MatrixXd& predicted,
                           const std::vector<double>& band) {
  SpectrumView v;
  v.band = band;
  const double lo = band.size() == 2 ? 0.5 * band[0] : 0.0, hi = band.size() == 2 ? 2.0 * band[1] : INFINITY;
  for (Eigen::Index k = 0; k < measured.cols(); ++k) {
    double top = 0.0, floor = INFINITY;
    for (std::size_t b = 0; b < f.size(); ++b) {
      if (f[b] < lo || f[b] > hi) continue;
      const auto i = static_cast<Eigen::Index>(b);
      const double m = measured(i, k), p = predicted.rows() > i ? predicted(i, k) : 0.0;
      if (std::isfinite(m)) top = std::max(top, m);
      if (std::isfinite(p)) top = std::max(top, p);
      if (std::isfinite(m) && m > 0) floor = std::min(floor, m);
    }
    if (!(top > 0) || !std::isfinite(floor)) {
      v.psd_range.emplace_back(0.0, 0.0);
      continue;
    }
    v.psd_range.emplace_back(std::max(floor, 1e-9 * top) / 3.0, 10.0 * top);
  }
  return v;
}

std::string spectrum_plot_script(const std::vector<std::string>& sensors, const std::vector<std::string>& units,
                                 const std::vector<double>& modes_hz, const std::string& title, const SpectrumView& view,
                                 const std::string& csv, const std::string& png) {
  const std::size_t ns = sensors.size();
  std::string gp = "set terminal pngcairo size 1000," + std::to_string(300 * ns + 40) + " noenhanced\nset output " +
                   gnuplot_quote(png) + "\nset datafile separator ','\nset multiplot layout " + std::to_string(ns) + ",1" +
                   (title.empty() ? std::string() : " title " + gnuplot_quote(title)) +
                   "\nset grid\nset key top right\nset logscale xy\nset format y '%g'\nset xlabel 'frequency [Hz]'\n";
  for (double f : modes_hz)
    if (std::isfinite(f) && f > 0) gp += "set arrow from " + io::format_value(f) + ", graph 0 to " + io::format_value(f) + ", graph 1 nohead front lc rgb 'red' dt 2\n";
  if (view.band.size() == 2 && view.band[0] > 0 && view.band[1] > view.band[0]) {
    gp += "set xrange [" + io::format_value(0.5 * view.band[0]) + ":" + io::format_value(2.0 * view.band[1]) + "]\n";
    for (double f : view.band)
      gp += "set arrow from " + io::format_value(f) + ", graph 0 to " + io::format_value(f) + ", graph 1 nohead front lc rgb 'blue' lw 2\n";
  }
  for (std::size_t k = 0; k < ns; ++k) {
    if (k < view.psd_range.size() && view.psd_range[k].second > view.psd_range[k].first && view.psd_range[k].first > 0)
      gp += "set yrange [" + io::format_value(view.psd_range[k].first) + ":" + io::format_value(view.psd_range[k].second) + "]\n";
    else
      gp += "set autoscale y\n";
    const std::string unit = k < units.size() && !units[k].empty() ? " [(" + units[k] + ")^2/Hz]" : "";
    gp += "set title " + gnuplot_quote(sensors[k] + " (the model's natural frequencies dashed" +
                                       (view.band.size() == 2 ? std::string(", the fitted band's edges solid)") : std::string(")"))) +
          "\nset ylabel " +
          gnuplot_quote("PSD" + unit) + "\n";
    gp += "plot " + gnuplot_quote(csv) + " every ::1 using 1:" + std::to_string(2 + 2 * k) +
          " with lines lw 2 title 'measured', '' every ::1 using 1:" + std::to_string(3 + 2 * k) + " with lines dt 2 lw 2 title 'predicted'\n";
  }
  gp += "unset multiplot\n";
  return gp;
}

void write_plot_binary(const std::string& path, const io::DataTable& tab) {
  std::vector<double> rows;
  rows.reserve(tab.t.size() * (tab.columns.size() + 1));
  for (std::size_t i = 0; i < tab.t.size(); ++i) {
    rows.push_back(tab.t[i]);
    for (const auto& c : tab.columns) rows.push_back(c[i]);
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(rows.data()), static_cast<std::streamsize>(rows.size() * sizeof(double)));
  if (!out) throw std::runtime_error("cannot write " + path);
}

namespace {
RenderStatus status_of(const io::ProcessResult& r) {
  if (!r.started) return RenderStatus::NoGnuplot;
  return r.ok() ? RenderStatus::Rendered : RenderStatus::Failed;
}
}  // namespace

RenderStatus render_gnuplot(const std::string& dir, const std::string& script) {
  return status_of(io::run_program({"gnuplot", script}, dir));
}

std::vector<RenderStatus> render_gnuplot(const std::string& dir, const std::vector<std::string>& scripts) {
  std::vector<std::vector<std::string>> argvs;
  for (const auto& s : scripts) argvs.push_back({"gnuplot", s});
  std::vector<RenderStatus> out;
  for (const auto& r : io::run_programs(argvs, dir)) out.push_back(status_of(r));
  return out;
}

std::vector<RenderStatus> render_fit_plots(const std::string& dir, const std::vector<FitPlot>& plots,
                                           const std::vector<std::string>& scripts) {
  std::vector<std::string> all, temporary;
  // The copies and their scripts go whatever happens (an interrupt propagates from the render).
  struct Cleanup {
    const std::vector<std::string>& files;
    ~Cleanup() {
      std::error_code ec;
      for (const auto& f : files) std::filesystem::remove(f, ec);
    }
  } cleanup{temporary};
  for (std::size_t i = 0; i < plots.size(); ++i) {
    const FitPlot& fp = plots[i];
    const std::string stem = ".fit-plot-" + std::to_string(i);
    const std::string data = (std::filesystem::path(dir) / (stem + ".f64")).string(),
                      script = (std::filesystem::path(dir) / (stem + ".gp")).string();
    temporary.insert(temporary.end(), {data, script});
    write_plot_binary(data, *fp.table);
    std::ofstream out(script, std::ios::trunc);
    out << fit_plot_script(fp.sensors, fp.cost, stem + ".f64", fp.png, fp.notes, static_cast<int>(fp.table->columns.size()) + 1);
    if (!out) throw std::runtime_error("cannot write " + script);
    all.push_back(stem + ".gp");
  }
  all.insert(all.end(), scripts.begin(), scripts.end());
  return render_gnuplot(dir, all);
}

io::DataTable frf_fit_table(const io::FrfData& d, const Eigen::MatrixXcd& model) {
  io::DataTable tab;
  tab.t = d.f_hz;
  tab.time_name = "frequency_hz";
  const bool have_model = model.rows() == d.lines() && model.cols() == static_cast<Eigen::Index>(d.channels.size());
  for (std::size_t s = 0; s < d.channels.size(); ++s) {
    const auto& ch = d.channels[s];
    const std::string& n = ch.sensor;
    tab.names.insert(tab.names.end(), {n + "_measured_re", n + "_measured_im", n + "_model_re", n + "_model_im", n + "_measured_magnitude",
                                       n + "_model_magnitude", n + "_measured_phase_deg", n + "_model_phase_deg", n + "_std"});
    std::vector<std::vector<double>> c(9);
    for (std::size_t k = 0; k < d.f_hz.size(); ++k) {
      const std::complex<double> hm = ch.H[k];
      const std::complex<double> hp = have_model ? model(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(s))
                                                 : std::complex<double>(std::nan(""), std::nan(""));
      const double vals[9] = {hm.real(), hm.imag(), hp.real(), hp.imag(), std::abs(hm), std::abs(hp),
                              std::arg(hm) * 180.0 / M_PI, std::arg(hp) * 180.0 / M_PI, std::sqrt(ch.variance[k])};
      for (int j = 0; j < 9; ++j) c[static_cast<std::size_t>(j)].push_back(vals[j]);
    }
    for (auto& col : c) tab.columns.push_back(std::move(col));
  }
  return tab;
}

std::string frf_plot_script(const io::FrfData& d, const std::string& input, const std::string& title, const std::string& csv,
                            const std::string& png) {
  const auto S = d.channels.size();
  const std::string file = gnuplot_quote(csv);
  std::string gp = "set terminal pngcairo size 1200," + std::to_string(300 * S + 60) + " noenhanced\nset output " + gnuplot_quote(png) +
                   "\nset datafile separator ','\nset multiplot layout " + std::to_string(S) + ",2 title " +
                   gnuplot_quote(title + " (FRFs per unit of '" + input + "'" +
                                 (d.decay > 0 ? ", at s = " + io::format_value(std::round(d.decay * 1e3) / 1e3) + "/s + i omega: windowed" : std::string()) + ")") +
                   "\nset grid\nset key top right\nset xlabel 'frequency [Hz]'\nset logscale x\nset xrange [" +
                   io::format_value(d.f_hz.front()) + ":" + io::format_value(d.f_hz.back()) + "]\n";
  for (std::size_t s = 0; s < S; ++s) {
    const std::string& n = d.channels[s].sensor;
    const int base = 2 + 9 * static_cast<int>(s);
    gp += "set logscale y\nset format y '%g'\nset yrange [*:*]\nset title " + gnuplot_quote(n + ": |H|") + "\nplot " + file + " every ::1 using 1:" +
          std::to_string(base + 4) + " with points pt 7 ps 0.4 title 'measured', '' every ::1 using 1:" + std::to_string(base + 5) +
          " with lines lw 2 title 'model at the estimate'\n";
    gp += "unset logscale y\nset yrange [-180:180]\nset ytics 90\nset title " + gnuplot_quote(n + ": phase [deg]") +
          "\nplot " + file + " every ::1 using 1:" + std::to_string(base + 6) + " with points pt 7 ps 0.4 title 'measured', '' every ::1 using 1:" +
          std::to_string(base + 7) + " with lines lw 2 title 'model'\nset ytics autofreq\n";
  }
  return gp + "unset multiplot\n";
}

}  // namespace scoleid::identify
