#include "scoleid/identify/run/fit_plot.h"

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
                            const std::string& csv, const std::string& png) {
  const std::size_t ns = sensors.size();
  const std::string data = gnuplot_quote(csv);
  std::string gp = "set terminal pngcairo size 1000," + std::to_string(300 * (ns + 1)) + " noenhanced\nset output " +
                   gnuplot_quote(png) + "\nset datafile separator ','\nset multiplot layout " + std::to_string(ns + 1) +
                   ",1\nset grid\nset key top right\n";
  for (std::size_t k = 0; k < ns; ++k) {
    const std::size_t c = 2 + 3 * k;
    gp += "set title " + gnuplot_quote(sensors[k]) + "\nset xlabel 't'\nset y2tics\nset ytics nomirror\n";
    gp += "plot " + data + " every ::1 using 1:" + std::to_string(c) + " with lines lw 2 title 'measured', '' every ::1 using 1:" +
          std::to_string(c + 1) + " with lines dt 2 lw 2 title 'predicted', '' every ::1 using 1:" + std::to_string(c + 2) +
          " axes x1y2 with lines lc rgb 'gray' title 'residual (right axis)'\n";
  }
  gp += "unset y2tics\nset ytics mirror\nset title 'cost per iteration'\nset xlabel 'iteration'\nset logscale y\n"
        "plot '-' using 1:2 with linespoints lw 2 notitle\n";
  for (const auto& [k, c] : cost) gp += std::to_string(k) + "," + io::format_value(c) + "\n";
  gp += "e\nunset multiplot\n";
  return gp;
}

RenderStatus render_gnuplot(const std::string& dir, const std::string& script) {
  const io::ProcessResult r = io::run_program({"gnuplot", script}, dir);
  if (!r.started) return RenderStatus::NoGnuplot;
  return r.ok() ? RenderStatus::Rendered : RenderStatus::Failed;
}

}  // namespace scoleid::identify
