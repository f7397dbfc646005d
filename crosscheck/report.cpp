#include "scoleid/crosscheck/report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "scoleid/crosscheck/json_shape.h"
#include "scoleid/crosscheck/table.h"
#include "scoleid/identify/run/fit_plot.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"

namespace scoleid::crosscheck {

namespace fs = std::filesystem;

namespace {
double num(const nlohmann::json& v) {
  return v.is_number() ? v.get<double>() : std::numeric_limits<double>::quiet_NaN();
}
std::string pct(double v) { return std::isfinite(v) ? percent(v, 2) + " %" : "n/a"; }
using identify::gnuplot_quote;

// Largest |extrapolated/FE − 1| over the first `k` modes, and the smallest MAC diagonal.
void mode_agreement(const nlohmann::json& m, std::size_t k, double& worst, double& mac, std::size_t& used) {
  worst = 0.0;
  mac = 1.0;
  used = 0;
  for (const auto& e : m["modes"]) {
    if (used == k) break;
    worst = std::max(worst, std::abs(num(e["extrapolated_vs_fe"])));
    mac = std::min(mac, num(e["mac"]));
    ++used;
  }
}
}  // namespace

namespace {


void check_modes(const nlohmann::json& m, const std::string& file) {
  const Shape s(file);
  if (!m.is_object()) s.fail("(top level)", "an object", &m);
  s.text(m, "scenario", "");
  const std::size_t levels = s.array(m, "segments", "", 0, "segment counts", is_count).size();
  s.each(m, "modes", "", [&](const nlohmann::json& mode, const std::string& w) {
    s.count(mode, "index", w);
    s.array(mode, "chain_hz", w, levels, "numbers", is_number_or_null);
    s.array(mode, "fe_hz", w, 0, "numbers", is_number_or_null);
    for (const char* key : {"chain_extrapolated_hz", "analytic_hz", "extrapolated_vs_fe", "chain_rate", "fe_rate", "mac"})
      s.number(mode, key, w);
  }, true);
}

void check_trajectories(const nlohmann::json& t, const std::string& file) {
  const Shape s(file);
  if (!t.is_object()) s.fail("(top level)", "an object", &t);
  s.text(t, "scenario", "");
  const std::size_t levels = s.array(t, "segments", "", 0, "segment counts", is_count).size();
  s.count(t, "elements", "");
  s.each(t, "sensors", "", [&](const nlohmann::json& sensor, const std::string& w) {
    s.text(sensor, "name", w);
    s.text(sensor, "kind", w);
    s.array(sensor, "relative_rms", w, levels, "numbers", is_number_or_null);
    s.number(sensor, "rate", w);
  }, true);
}

void check_identify(const nlohmann::json& id, const std::string& file) {
  const Shape s(file);
  if (!id.is_object()) s.fail("(top level)", "an object", &id);
  s.text(id, "scenario", "");
  s.text(id, "data", "");
  s.flag(id, "all_converged", "");
  const std::size_t levels = s.array(id, "segments", "", 0, "segment counts", is_count).size();
  s.each(id, "parameters", "", [&](const nlohmann::json& p, const std::string& w) {
    s.text(p, "name", w);
    s.number(p, "truth", w);
    for (const char* key : {"extrapolated_relative_error", "observed_rate", "fe_on_fe_relative_error"})
      s.number(p, key, w);
    s.array(p, "relative_error", w, levels, "numbers", is_number_or_null);
    s.array(p, "std", w, levels, "numbers", is_number_or_null);
    s.array(p, "covered_by_2std", w, levels, "true or false", is_flag);
    if (p.contains("half_width")) s.array(p, "half_width", w, levels, "numbers", is_number_or_null);
    if (p.contains("half_width") || p.contains("covered_by_interval"))
      s.array(p, "covered_by_interval", w, levels, "true or false", is_flag);
  }, true);
}

// The verbs' files, each with its shape check, in the order they are read.
using ShapeCheck = void (*)(const nlohmann::json&, const std::string&);
struct ReportFile {
  const char* name;
  ShapeCheck check;
  nlohmann::json ReportInputs::*member;
};
const ReportFile kReportFiles[] = {{"modes.json", check_modes, &ReportInputs::modes},
                                   {"trajectories.json", check_trajectories, &ReportInputs::trajectories},
                                   {"identify.json", check_identify, &ReportInputs::identify}};
}  // namespace

ReportInputs read_report_inputs(const std::string& dir) {
  ReportInputs in;
  for (const ReportFile& f : kReportFiles) {
    const fs::path p = fs::path(dir) / f.name;
    if (!fs::exists(p)) continue;
    in.*f.member = io::read_json(p.string());
    f.check(in.*f.member, p.string());
  }
  return in;
}

void check_report_inputs(const ReportInputs& in, const std::string& dir) {
  for (const ReportFile& f : kReportFiles)
    if (!(in.*f.member).is_null()) f.check(in.*f.member, (fs::path(dir) / f.name).string());
}

std::vector<std::string> summary_lines(const ReportInputs& in) {
  std::vector<std::string> out;
  if (!in.modes.is_null()) {
    double worst, mac;
    std::size_t k;
    mode_agreement(in.modes, 5, worst, mac, k);
    const auto& seg = in.modes["segments"];
    out.push_back("modes         first " + std::to_string(k) + " flexible frequencies: chain (n = " +
                  std::to_string(seg.front().get<int>()) + ".." + std::to_string(seg.back().get<int>()) +
                  ", extrapolated) and FE agree to " + pct(worst) + "; MAC diagonal >= " + number(mac, 6));
  }
  if (!in.trajectories.is_null()) {
    double worst = 0.0;
    std::string who;
    for (const auto& s : in.trajectories["sensors"]) {
      const double d = num(s["relative_rms"].back());
      if (std::isfinite(d) && d >= worst) {
        worst = d;
        who = s["name"].get<std::string>();
      }
    }
    out.push_back("trajectories  chain (n = " + std::to_string(in.trajectories["segments"].back().get<int>()) +
                  ") and FE agree to " + pct(worst) + " relative RMS (worst sensor: " + who + ")");
  }
  if (!in.identify.is_null()) {
    double worst = 0.0, worst_x = 0.0, worst_fe = 0.0;
    int covered = 0, total = 0, icovered = 0;
    for (const auto& p : in.identify["parameters"]) {
      worst = std::max(worst, std::abs(num(p["relative_error"].front())));
      worst_x = std::max(worst_x, std::abs(num(p["extrapolated_relative_error"])));
      worst_fe = std::max(worst_fe, std::abs(num(p["fe_on_fe_relative_error"])));
      covered += p["covered_by_2std"].front().get<bool>() ? 1 : 0;
      icovered += p.contains("covered_by_interval") && p["covered_by_interval"].front().get<bool>() ? 1 : 0;
      ++total;
    }
    const int n = in.identify["segments"].front().get<int>();
    out.push_back("parameters    within " + pct(worst) + " of the truth at n = " + std::to_string(n) + "; " + pct(worst_x) +
                  " extrapolated in n; FE-on-FE " + pct(worst_fe) +
                  (in.identify["all_converged"].get<bool>() ? "" : "  (NOT all runs converged)"));
    out.push_back("uncertainty   at n = " + std::to_string(n) + " the reported interval covers the error for " +
                  std::to_string(icovered) + " of " + std::to_string(total) + " parameters, +-2 std for " +
                  std::to_string(covered) + (covered == total ? "" : " (the std measures the noise, not the model error)"));
  }
  return out;
}

namespace {

// The natural frequencies' section: the table, and the convergence of the chain against the finest
// FE model as a plot (modes_convergence.csv, modes.gp).
std::string modes_section(const nlohmann::json& modes, ReportFiles& rf) {
  std::string md;
  const auto& m = modes;
  Table t;
  t.header = {"mode", "chain extrap. [Hz]", "FE finest [Hz]", "analytic [Hz]", "extrap./FE-1 %", "rate n", "rate N", "MAC"};
  Table conv;
  conv.header = {"n"};
  const std::size_t plotted = std::min<std::size_t>(5, m["modes"].size());
  for (std::size_t k = 0; k < plotted; ++k) conv.header.push_back("mode" + std::to_string(k + 1));
  for (std::size_t l = 0; l < m["segments"].size(); ++l) {
    std::vector<std::string> row{std::to_string(m["segments"][l].get<int>())};
    for (std::size_t k = 0; k < plotted; ++k) {
      const auto& e = m["modes"][k];
      row.push_back(number(std::abs(num(e["chain_hz"][l]) / num(e["fe_hz"].back()) - 1.0), 6));
    }
    conv.rows.push_back(row);
  }
  for (const auto& e : m["modes"])
    t.rows.push_back({std::to_string(e["index"].get<int>()), number(num(e["chain_extrapolated_hz"]), 7),
                      number(num(e["fe_hz"].back()), 7),
                      std::isfinite(num(e["analytic_hz"])) ? number(num(e["analytic_hz"]), 7) : "-",
                      percent(num(e["extrapolated_vs_fe"]), 3), number(num(e["chain_rate"]), 3),
                      number(num(e["fe_rate"]), 3), number(num(e["mac"]), 6)});
  rf.files.push_back({"modes_convergence.csv", conv.csv()});
  std::string gp = "set terminal pngcairo noenhanced size 900,600\nset output 'modes.png'\nset datafile separator ','\n"
                   "set logscale xy\nset format y '%.0e'\nset key outside right\nset grid\nset xlabel 'chain segments n'\n"
                   "set ylabel '|f_chain(n) / f_FE - 1|'\nset title " +
                   gnuplot_quote("Natural frequencies, " + m["scenario"].get<std::string>() + ": chain against the finest FE") +
                   "\nplot ";
  for (std::size_t k = 0; k < plotted; ++k)
    gp += "'modes_convergence.csv' using 1:" + std::to_string(k + 2) + " with linespoints title 'mode " +
          std::to_string(k + 1) + "', ";
  const double y0 = conv.rows.empty() ? 1e-3 : std::max(1e-12, std::atof(conv.rows.front().back().c_str()));
  gp += number(y0, 6) + "*(" + std::to_string(m["segments"].front().get<int>()) + "/x)**2 dashtype 2 title 'n^-2'\n";
  rf.files.push_back({"modes.gp", gp});
  rf.scripts.push_back("modes.gp");
  md += "\n## Natural frequencies\n\n" + t.markdown() + "\nCSV: `modes.csv`, `mac.csv`, `modes_convergence.csv`.\n\n![modes](modes.png)\n";
  return md;
}

// The trajectories' section: relative RMS per sensor and level, and the overlay plot of the finest
// chain against the FE model when overlay.csv is there.
std::string trajectories_section(const nlohmann::json& trajectories, bool overlay_csv_present, ReportFiles& rf) {
  std::string md;
  const auto& tr = trajectories;
  Table t;
  t.header = {"sensor", "kind"};
  for (const auto& n : tr["segments"]) t.header.push_back("n=" + std::to_string(n.get<int>()) + " %");
  t.header.push_back("rate");
  for (const auto& s : tr["sensors"]) {
    std::vector<std::string> row{s["name"].get<std::string>(), s["kind"].get<std::string>()};
    for (const auto& d : s["relative_rms"]) row.push_back(percent(num(d), 3));
    row.push_back(number(num(s["rate"]), 3));
    t.rows.push_back(row);
  }
  md += "\n## Trajectories\n\nRelative RMS difference between the chain and the FE model (N = " +
        std::to_string(tr["elements"].get<int>()) + ") at the truth's parameters.\n\n" + t.markdown() +
        "\nCSV: `trajectories.csv`, `overlay.csv` (finest n).\n";
  if (overlay_csv_present) {
    const auto& sensors = tr["sensors"];
    const std::size_t k = std::min<std::size_t>(4, sensors.size());
    std::string gp = "set terminal pngcairo noenhanced size 1000," + std::to_string(300 * k) +
                     "\nset output 'overlay.png'\nset datafile separator ','\nset key autotitle columnhead\n"
                     "set multiplot layout " + std::to_string(k) + ",1\nset grid\nset y2tics\nset ytics nomirror\n";
    for (std::size_t i = 0; i < k; ++i) {
      const int c = 2 + 3 * static_cast<int>(i);
      gp += "set title " + gnuplot_quote(sensors[i]["name"].get<std::string>() + " (" + sensors[i]["kind"].get<std::string>() + ")") +
            "\nset y2label 'chain - FE'\nplot 'overlay.csv' using 1:" + std::to_string(c) +
            " with lines title 'chain', '' using 1:" + std::to_string(c + 1) + " with lines dashtype 2 title 'FE', '' using 1:" +
            std::to_string(c + 2) + " axes x1y2 with lines lc rgb 'gray' title 'residual (right)'\n";
    }
    gp += "unset multiplot\n";
    rf.files.push_back({"overlay.gp", gp});
    rf.scripts.push_back("overlay.gp");
    md += "\n![overlay](overlay.png)\n";
  }
  return md;
}

// The identification's section: errors per level, extrapolated, FE-on-FE, std and interval
// coverage, and the convergence plot (identify_convergence.csv, identify.gp).
std::string identify_section(const nlohmann::json& identify, ReportFiles& rf) {
  std::string md;
  const auto& id = identify;
  Table t;
  t.header = {"parameter", "truth"};
  for (const auto& n : id["segments"]) t.header.push_back("n=" + std::to_string(n.get<int>()) + " %");
  t.header.insert(t.header.end(), {"extrapolated %", "rate", "FE-on-FE %", "2 std (n) %", "covered", "± interval (n) %", "covered"});
  Table conv;
  conv.header = {"n"};
  for (const auto& p : id["parameters"]) conv.header.push_back(p["name"].get<std::string>());
  for (std::size_t l = 0; l < id["segments"].size(); ++l) {
    std::vector<std::string> row{std::to_string(id["segments"][l].get<int>())};
    for (const auto& p : id["parameters"]) row.push_back(number(std::abs(num(p["relative_error"][l])), 6));
    conv.rows.push_back(row);
  }
  for (const auto& p : id["parameters"]) {
    std::vector<std::string> row{p["name"].get<std::string>(), number(num(p["truth"]), 7)};
    for (const auto& e : p["relative_error"]) row.push_back(percent(num(e), 3));
    row.push_back(percent(num(p["extrapolated_relative_error"]), 3));
    row.push_back(number(num(p["observed_rate"]), 3));
    row.push_back(percent(num(p["fe_on_fe_relative_error"]), 3));
    row.push_back(percent(2.0 * num(p["std"].front()) / std::abs(num(p["truth"])), 3));
    row.push_back(p["covered_by_2std"].front().get<bool>() ? "yes" : "no");
    const bool has = p.contains("half_width") && p["half_width"].front().is_number();
    row.push_back(has ? percent(num(p["half_width"].front()) / std::abs(num(p["truth"])), 3) : "-");
    row.push_back(has ? (p["covered_by_interval"].front().get<bool>() ? "yes" : "no") : "flagged");
    t.rows.push_back(row);
  }
  rf.files.push_back({"identify_convergence.csv", conv.csv()});
  std::string gp = "set terminal pngcairo noenhanced size 900,600\nset output 'identify.png'\nset datafile separator ','\n"
                   "set logscale xy\nset format y '%.0e'\nset key outside right\nset grid\nset xlabel 'truth chain segments n'\n"
                   "set ylabel '|estimate / truth - 1|'\nset title " +
                   gnuplot_quote("Identification on the Simbody truth, " + id["scenario"].get<std::string>()) + "\nplot ";
  int col = 2;
  for (const auto& p : id["parameters"]) {
    const std::string name = p["name"].get<std::string>();
    gp += "'identify_convergence.csv' using 1:" + std::to_string(col++) + " with linespoints title " + gnuplot_quote(name) + ", ";
    const double x = std::abs(num(p["extrapolated_relative_error"]));
    if (std::isfinite(x) && x > 0)
      gp += number(x, 6) + " dashtype 2 title " + gnuplot_quote(name + " extrapolated") + ", ";
    const double f = std::abs(num(p["fe_on_fe_relative_error"]));
    if (std::isfinite(f) && f > 0) gp += number(f, 6) + " dashtype 3 title " + gnuplot_quote(name + " FE-on-FE") + ", ";
  }
  gp.resize(gp.size() - 2);
  gp += "\n";
  rf.files.push_back({"identify.gp", gp});
  rf.scripts.push_back("identify.gp");
  md += "\n## Identification\n\n" + id["data"].get<std::string>() + "; the chain's lumping bias extrapolated as n^-2 "
        "from the two finest truths; FE-on-FE: the same identification on synthetic FE data.\n\n" + t.markdown() +
        "\nCSV: `identify.csv`, `identify_convergence.csv`.\n\n![identify](identify.png)\n";
  return md;
}

}  // namespace

ReportFiles make_report(const ReportInputs& in, bool overlay_csv_present) {
  ReportFiles rf;
  std::string md = "# Cross-check report";
  const nlohmann::json& any = !in.modes.is_null() ? in.modes : !in.trajectories.is_null() ? in.trajectories : in.identify;
  if (!any.is_null()) md += ": " + any["scenario"].get<std::string>();
  md += "\n\nThe Simbody truth (a chain of n rigid segments) against the finite-element identifier (N elements).\n"
        "Regenerate with `scole-crosscheck report --out DIR` after the verbs.\n\n## Summary\n\n```\n";
  for (const auto& l : summary_lines(in)) md += l + "\n";
  md += "```\n";

  if (!in.modes.is_null()) md += modes_section(in.modes, rf);
  if (!in.trajectories.is_null()) md += trajectories_section(in.trajectories, overlay_csv_present, rf);
  if (!in.identify.is_null()) md += identify_section(in.identify, rf);
  rf.files.push_back({"report.md", md});
  return rf;
}

}  // namespace scoleid::crosscheck
