#include "scoleid/crosscheck/campaign.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include "scoleid/crosscheck/scenario_overlay.h"
#include "study_yaml.h"
#include "scoleid/crosscheck/table.h"
#include "scoleid/identify/door/scenario_door.h"
#include "scoleid/identify/fe/structure.h"
#include "scoleid/io/error.h"
#include "scoleid/io/input_file.h"
#include "scoleid/io/interrupt.h"

namespace scoleid::crosscheck {

using nlohmann::json;

namespace {

using study::bad;
using study::number_of;
using study::text_of;

bool name_ok(const std::string& s, const char* extra) {
  if (s.empty()) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || std::string(extra).find(c) != std::string::npos)) return false;
  return true;
}

// FNV-1a, 64 bits, as 16 hex digits: a fingerprint of a case's inputs (not a security hash).
std::string fingerprint(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

// grid: {dotted.path: [values]}, every value distinct (also as 10 and 10.0).
void parse_grid(const YAML::Node& g, const std::string& path, Campaign& c) {
  if (!g.IsMap()) bad(path, "grid", "must be a map {dotted.path: [values]}", text_of(g));
  for (const auto& kv : g) {
    const std::string p = kv.first.as<std::string>(), field = "grid." + p;
    if (!name_ok(p, "-_.") || p.front() == '.' || p.back() == '.' || p.find("..") != std::string::npos)
      bad(path, "grid", "keys must be dotted scenario paths (e.g. truth.segments)", "'" + p + "'");
    if (!kv.second.IsSequence() || kv.second.size() == 0) bad(path, field, "must be a non-empty list of values", text_of(kv.second));
    for (const auto& [q, v] : c.grid)
      if (q == p) bad(path, field, "is given twice", "'" + p + "'");
    std::vector<std::string> values;
    for (std::size_t i = 0; i < kv.second.size(); ++i) {
      const YAML::Node v = kv.second[i];
      if (!v || v.IsNull()) bad(path, field + "[" + std::to_string(i) + "]", "must be a value", "null");
      // The same value twice (also as 10 and 10.0) would be the same point twice.
      for (std::size_t j = 0; j < i; ++j) {
        const YAML::Node u = kv.second[j];
        bool same = text_of(u) == text_of(v);
        if (!same && u.IsScalar() && v.IsScalar()) {
          double a = 0, b = 0;
          same = YAML::convert<double>::decode(u, a) && YAML::convert<double>::decode(v, b) && a == b;
        }
        if (same) bad(path, field + "[" + std::to_string(i) + "]", "repeats an earlier value", text_of(v));
      }
      values.push_back(text_of(v));
    }
    c.grid.emplace_back(p, values);
  }
}

// noise: {relative: r, seeds: K, seed: first}.
void parse_noise(const YAML::Node& n, const std::string& path, Campaign& c) {
  if (!n.IsMap() || !n["relative"] || !n["seeds"]) bad(path, "noise", "must be {relative: r, seeds: K, seed: first}", text_of(n));
  for (const auto& kv : n) {
    const std::string k = kv.first.as<std::string>();
    if (k != "relative" && k != "seeds" && k != "seed") bad(path, "noise." + k, "is not a noise field (relative, seeds, seed)", "'" + k + "'");
  }
  c.noise_relative = number_of(n["relative"], path, "noise.relative");
  if (!(c.noise_relative > 0 && c.noise_relative < 1)) bad(path, "noise.relative", "must be in (0, 1)", n["relative"].Scalar());
  const double s = number_of(n["seeds"], path, "noise.seeds");
  if (!(s >= 2 && s <= 100000 && s == std::floor(s))) bad(path, "noise.seeds", "must be an integer in [2, 100000]", n["seeds"].Scalar());
  c.seeds = static_cast<int>(s);
  if (n["seed"]) {
    const double b = number_of(n["seed"], path, "noise.seed");
    if (!(b >= 0 && b < 4294967296.0 && b == std::floor(b))) bad(path, "noise.seed", "must be an integer in [0, 2^32)", n["seed"].Scalar());
    c.noise_seed = static_cast<unsigned>(b);
  }
}

// Points: scenarios × grid, last grid path fastest; each a different scenario, checked as the
// identifier would check it before anything runs.
void make_points(Campaign& c, const std::string& path) {
  std::unordered_map<std::string, std::size_t> keys;
  constexpr std::size_t kMaxPoints = 100000, kMaxCases = 1000000;
  std::size_t combos = 1;
  for (const auto& [p, v] : c.grid) {
    combos *= v.size();
    if (combos * c.scenarios.size() > kMaxPoints)
      bad(path, "grid", "gives more than " + std::to_string(kMaxPoints) + " points", "at '" + p + "'");
  }
  if (combos * c.scenarios.size() * static_cast<std::size_t>(c.seeds + 1) > kMaxCases)
    bad(path, "noise.seeds", "gives more than " + std::to_string(kMaxCases) + " cases with the grid's " +
                                 std::to_string(combos * c.scenarios.size()) + " points", std::to_string(c.seeds));
  // Each grid value first on its own (the other paths at their first value): a bad value is
  // refused in a moment, not after the points before it in the grid's order (a grid of 10⁵ points
  // takes minutes to check whole).
  for (const auto& s : c.scenarios)
    for (std::size_t a = 0; a < c.grid.size(); ++a)
      for (std::size_t k = 1; k < c.grid[a].second.size(); ++k) {
        io::check_interrupt();
        std::vector<std::string> overlays{c.overlay};
        std::string label = s;
        for (std::size_t b = 0; b < c.grid.size(); ++b) {
          const std::string& v = c.grid[b].second[b == a ? k : 0];
          overlays.push_back(path_overlay(c.grid[b].first, v));
          label += " " + c.grid[b].first + "=" + v;
        }
        checked_scenario(overlaid_scenario_yaml(s, path, "scenarios", overlays), path + " (" + label + ")");
      }
  for (const auto& s : c.scenarios)
    for (std::size_t g = 0; g < combos; ++g) {
      io::check_interrupt();  // checking 10⁵ points takes minutes
      std::vector<std::string> overlays{c.overlay};
      std::string label = s;
      std::size_t rest = g;
      std::vector<std::size_t> idx(c.grid.size());
      for (std::size_t a = c.grid.size(); a-- > 0;) {
        idx[a] = rest % c.grid[a].second.size();
        rest /= c.grid[a].second.size();
      }
      for (std::size_t a = 0; a < c.grid.size(); ++a) {
        const std::string& v = c.grid[a].second[idx[a]];
        overlays.push_back(path_overlay(c.grid[a].first, v));
        label += " " + c.grid[a].first + "=" + v;
      }
      CampaignPoint pt;
      char id[16];
      std::snprintf(id, sizeof id, "p%03zu", c.points.size());
      pt.id = id;
      pt.label = label;
      pt.yaml = overlaid_scenario_yaml(s, path, "scenarios", overlays);
      pt.key = fingerprint(pt.yaml);
      const std::string where = path + " (point " + pt.id + ": " + label + ")";
      pt.scenario = checked_scenario(pt.yaml, where);
      // The identifier's door, before anything runs (make_problem's).
      identify::check_identification(pt.scenario);
      if (const auto it = keys.find(pt.key); it != keys.end())
        bad(path, "grid", "gives the same scenario twice", "points " + c.points[it->second].label + " and " + label);
      keys[pt.key] = c.points.size();
      c.points.push_back(std::move(pt));
    }
}

// Cases: per point the noise-free identification and one per seed.
void make_cases(Campaign& c) {
  for (std::size_t p = 0; p < c.points.size(); ++p)
    for (int s = -1; s < c.seeds; ++s) {
      CampaignCase k;
      k.point = p;
      k.seed = s;
      char id[32];
      if (s < 0)
        std::snprintf(id, sizeof id, "%s-ref", c.points[p].id.c_str());
      else
        std::snprintf(id, sizeof id, "%s-s%04d", c.points[p].id.c_str(), s);
      k.id = id;
      // The noise-free case depends on the point alone; a draw on the noise settings too.
      char noise[96];
      std::snprintf(noise, sizeof noise, "|seed %d|relative %.17g|base %u", s, c.noise_relative, c.noise_seed);
      k.key = fingerprint(c.points[p].yaml + (s < 0 ? std::string("|noise-free") : std::string(noise)));
      c.cases.push_back(std::move(k));
    }
}

Campaign load_checked(const std::string& path) {
  Campaign c;
  c.path = path;
  YAML::Node root;
  try {
    const std::string text = io::read_text_file(path, "campaign file");
    io::check_yaml_nesting(text, "campaign file '" + path + "'");
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw io::InputError("campaign file '" + path + "': malformed YAML: " + e.msg + " (line " + std::to_string(e.mark.line + 1) + ")");
  }
  io::check_yaml_document(root, "campaign file '" + path + "'", true);
  if (!root.IsMap()) bad(path, "(top level)", "must be a map", "");
  static const std::vector<std::string> known = {"campaign", "description", "scenarios", "overlay", "grid", "noise"};
  std::vector<std::string> seen;
  for (const auto& kv : root) {
    const std::string k = kv.first.as<std::string>();
    if (std::find(known.begin(), known.end(), k) == known.end()) bad(path, k, "is not a campaign field", "'" + k + "'");
    if (std::find(seen.begin(), seen.end(), k) != seen.end()) bad(path, k, "is given twice", "'" + k + "'");
    seen.push_back(k);
  }
  if (!root["campaign"] || !root["campaign"].IsScalar()) bad(path, "campaign", "is required (the campaign's name)", "none");
  c.name = root["campaign"].Scalar();
  if (!name_ok(c.name, "-_")) bad(path, "campaign", "must be letters, digits, - and _", "'" + c.name + "'");
  if (root["description"]) {
    if (!root["description"].IsScalar()) bad(path, "description", "must be text", text_of(root["description"]));
    c.description = root["description"].Scalar();
  }
  const YAML::Node sc = root["scenarios"];
  if (!sc || !sc.IsSequence() || sc.size() == 0) bad(path, "scenarios", "must be a non-empty list of scenario names or files", sc ? text_of(sc) : "none");
  for (std::size_t i = 0; i < sc.size(); ++i) {
    if (!sc[i].IsScalar() || sc[i].Scalar().empty()) bad(path, "scenarios[" + std::to_string(i) + "]", "must be a scenario name or file", text_of(sc[i]));
    if (std::find(c.scenarios.begin(), c.scenarios.end(), sc[i].Scalar()) != c.scenarios.end())
      bad(path, "scenarios[" + std::to_string(i) + "]", "is listed twice", "'" + sc[i].Scalar() + "'");
    c.scenarios.push_back(sc[i].Scalar());
  }
  if (root["overlay"]) {
    if (!root["overlay"].IsMap()) bad(path, "overlay", "must be a map of scenario fields", text_of(root["overlay"]));
    c.overlay = text_of(root["overlay"]);
  }
  if (const YAML::Node g = root["grid"]) parse_grid(g, path, c);
  if (const YAML::Node n = root["noise"]) parse_noise(n, path, c);
  make_points(c, path);
  make_cases(c);
  return c;
}

double val(const json& j, const char* k) {
  return j.contains(k) && j[k].is_number() ? j[k].get<double>() : std::nan("");
}

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

}  // namespace

Campaign load_campaign(const std::string& path) {
  try {
    return load_checked(path);
  } catch (const YAML::Exception& e) {
    throw io::InputError("campaign file '" + path + "': " + e.msg + " (line " + std::to_string(e.mark.line + 1) + ")");
  }
}

unsigned case_noise_seed(const Campaign& c, const CampaignCase& k) {
  return c.noise_seed + 1000003u * static_cast<unsigned>(k.point) + static_cast<unsigned>(std::max(k.seed, 0));
}

namespace {

// One row per case and parameter; the counts of failed and converged cases and the failures.
struct CaseRows {
  Table cases;
  int failed = 0, converged = 0;
  std::vector<std::string> failures;
};
CaseRows case_rows(const Campaign& c, const std::vector<json>& results) {
  CaseRows out;
  Table& cases = out.cases;
  int& failed = out.failed;
  int& converged = out.converged;
  std::vector<std::string>& failures = out.failures;
  cases = Table{"cases", {"case", "point", "seed", "parameter", "truth", "estimate", "relative_error", "std", "half_width",
                        "identifiable", "covered", "converged", "explains_data", "failed"}, {}};
  for (std::size_t k = 0; k < c.cases.size(); ++k) {
    const json& r = results.at(k);
    const CampaignCase& kc = c.cases[k];
    if (r.contains("failed")) {
      ++failed;
      failures.push_back(kc.id + ": " + r["failed"].get<std::string>());
      cases.rows.push_back({kc.id, c.points[kc.point].id, std::to_string(kc.seed), "", "", "", "", "", "", "", "", "", "", r["failed"].get<std::string>()});
      continue;
    }
    converged += r.value("converged", false) ? 1 : 0;
    for (const auto& q : r["parameters"])
      cases.rows.push_back({kc.id, c.points[kc.point].id, std::to_string(kc.seed), q["name"].get<std::string>(), number(val(q, "truth"), 12),
                            number(val(q, "estimate"), 12), number(val(q, "relative_error"), 6), number(val(q, "std"), 6),
                            number(val(q, "half_width"), 6), q["identifiable"].get<bool>() ? "yes" : "no",
                            q["covered"].get<bool>() ? "yes" : "no", r.value("converged", false) ? "yes" : "no",
                            r.value("explains_data", false) ? "yes" : "no", ""});
  }
  return out;
}

// Over a point's seeds (the draws whose estimate and std are finite numbers; the others are
// counted apart; scatter-based figures need two): the scatter against the reported std, the
// noise bias, the share within 1.96 std and the interval coverage of parameter i. Appends the
// cells to `row` and the figures to `js`, the normalised deviations to `zs`.
void seed_statistics(const std::vector<json>& results, const std::vector<std::size_t>& seeds, std::size_t i, double truth,
                     double ref_est, std::vector<std::string>& row, json& js, std::vector<double>& zs) {
  std::vector<std::pair<double, double>> es;  // (estimate, std)
  int conv = 0, covered = 0, within = 0;
  for (std::size_t k : seeds) {
    const json& sq = results[k]["parameters"][i];
    conv += results[k].value("converged", false) ? 1 : 0;
    covered += sq["covered"].get<bool>() ? 1 : 0;
    const double e = val(sq, "estimate"), sd = val(sq, "std");
    if (!std::isfinite(e) || !(sd > 0) || !std::isfinite(sd)) continue;
    es.emplace_back(e, sd);
    const double z = (e - ref_est) / sd;
    within += std::abs(z) <= 1.959964 ? 1 : 0;
    if (std::isfinite(z)) zs.push_back(z);
  }
  const int n = static_cast<int>(seeds.size()), m = static_cast<int>(es.size());
  double mean = 0, var = 0, std_mean = 0;
  for (const auto& [e, sd] : es) {
    mean += e / m;
    std_mean += sd / m;
  }
  for (const auto& [e, sd] : es) var += (e - mean) * (e - mean) / (m > 1 ? m - 1 : 1);
  const double scatter = m > 1 ? std::sqrt(var) : std::nan("");
  const double bias = m > 1 ? (mean - ref_est) / (scatter / std::sqrt(static_cast<double>(m))) : std::nan("");
  const double mean_err = m > 0 ? mean / truth - 1.0 : std::nan("");
  const double msd = m > 0 ? std_mean / std::abs(truth) : std::nan("");
  for (const std::string& cell : {std::to_string(n), std::to_string(m), std::to_string(conv), number(mean_err, 4),
                                  number(scatter / std::abs(truth), 4), number(msd, 4), number(scatter / std_mean, 4),
                                  number(bias, 3), number(m ? static_cast<double>(within) / m : std::nan(""), 4),
                                  number(static_cast<double>(covered) / n, 4)})
    row.push_back(cell);
  js["seeds"] = n;
  js["seeds_with_std"] = m;
  js["converged_seeds"] = conv;
  js["scatter_over_std"] = json_number(scatter / std_mean);
  js["noise_bias_std_of_mean"] = json_number(bias);
  js["within_1.96_std"] = json_number(m ? static_cast<double>(within) / m : std::nan(""));
  js["interval_coverage"] = json_number(static_cast<double>(covered) / n);
}

// Per point and parameter: the noise-free estimate, and over the seeds the scatter against the
// reported std and the coverage of the reported interval.
struct PointRows {
  Table points;
  std::map<std::string, std::vector<double>> z_by_name;  // (estimate - noise-free estimate) / std
  std::vector<std::string> name_order;
  json summary = json::array();
};
PointRows point_rows(const Campaign& c, const std::vector<json>& results) {
  PointRows out;
  Table& points = out.points;
  auto& z_by_name = out.z_by_name;
  auto& name_order = out.name_order;
  json& summary = out.summary;
  points = Table{"points", {"point", "label", "parameter", "truth", "ref_relative_error", "ref_relative_half_width", "ref_covered",
                          "seeds", "seeds_with_std", "converged_seeds", "mean_relative_error", "relative_scatter", "relative_mean_std",
                          "scatter_over_std", "noise_bias_std_of_mean", "within_1.96_std", "interval_coverage"}, {}};
  for (std::size_t p = 0; p < c.points.size(); ++p) {
    std::vector<std::size_t> seeds;
    std::size_t ref = c.cases.size();
    for (std::size_t k = 0; k < c.cases.size(); ++k) {
      if (c.cases[k].point != p || results[k].contains("failed")) continue;
      if (c.cases[k].seed < 0) ref = k;
      else seeds.push_back(k);
    }
    if (ref == c.cases.size()) continue;  // the reference failed: listed with the failures
    const json& rr = results[ref];
    for (std::size_t i = 0; i < rr["parameters"].size(); ++i) {
      const json& q = rr["parameters"][i];
      const std::string name = q["name"];
      if (!z_by_name.count(name)) name_order.push_back(name);
      auto& zs = z_by_name[name];
      const double truth = val(q, "truth"), ref_est = val(q, "estimate");
      std::vector<std::string> row{c.points[p].id, c.points[p].label, name, number(truth, 10), number(val(q, "relative_error"), 4),
                                   number(val(q, "relative_half_width"), 4), q["covered"].get<bool>() ? "yes" : "no"};
      json js{{"point", c.points[p].id}, {"label", c.points[p].label}, {"parameter", name},
              {"ref_relative_error", json_number(val(q, "relative_error"))}, {"ref_covered", q["covered"]}};
      if (!seeds.empty()) {
        seed_statistics(results, seeds, i, truth, ref_est, row, js, zs);
      } else {
        for (int j = 0; j < 10; ++j) row.push_back("");
      }
      points.rows.push_back(row);
      summary.push_back(js);
    }
  }
  return out;
}

// Histogram of z = (estimate - ref) / std, per parameter, with the standard normal's counts: the
// CSV and the gnuplot script.
std::pair<std::string, std::string> z_histogram(const PointRows& pr) {
  const auto& name_order = pr.name_order;
  std::string hist = "parameter,bin_low,bin_high,count,normal_expected\n";
  std::ostringstream gp;
  const double w = 0.5, lo = -4.0;
  const int bins = 16;
  gp << "# Histogram of (estimate - noise-free estimate) / reported std over the seeds, per parameter, against the\n"
     << "# standard normal (gnuplot histogram.gp)\nset terminal pngcairo noenhanced size " << 500 * name_order.size()
     << ",400 font ',10'\nset output 'histogram.png'\nset multiplot layout 1," << name_order.size()
     << "\nset grid\nset style fill solid 0.5\nset xlabel '(estimate - noise-free estimate) / reported std'\nset ylabel 'seeds'\n";
  for (const auto& name : name_order) {
    const auto& zs = pr.z_by_name.at(name);
    std::string block;
    int under = 0, over = 0;
    for (double z : zs) {
      if (!(z >= lo)) ++under;
      if (!(z < lo + bins * w)) ++over;
    }
    for (int b = 0; b < bins; ++b) {
      const double a = lo + b * w, e = a + w;
      const auto cnt = std::count_if(zs.begin(), zs.end(), [&](double z) { return z >= a && z < e; });
      const double expected = static_cast<double>(zs.size()) * (normal_cdf(e) - normal_cdf(a));
      char buf[160];
      std::snprintf(buf, sizeof buf, "%s,%.2f,%.2f,%ld,%.4f\n", name.c_str(), a, e, static_cast<long>(cnt), expected);
      hist += buf;
      std::snprintf(buf, sizeof buf, "%.2f %ld %.4f\n", a + 0.5 * w, static_cast<long>(cnt), expected);
      block += buf;
    }
    gp << "set title '" << name << ": " << zs.size() << " seeds (" << under + over << " outside [-4, 4])'\n"
       << "plot '-' using 1:2 with boxes title 'seeds', '-' using 1:3 with linespoints lw 2 title 'standard normal'\n"
       << block << "e\n" << block << "e\n";
  }
  gp << "unset multiplot\n";
  return {hist, gp.str()};
}

}  // namespace

std::map<std::string, std::string> campaign_report(const Campaign& c, const std::vector<json>& results) {
  std::map<std::string, std::string> files;
  std::ostringstream md;
  md << "# Campaign " << c.name << "\n\n";
  if (!c.description.empty()) md << c.description << "\n\n";
  md << "Points: " << c.points.size() << " (scenarios × grid); cases: " << c.cases.size() << " (per point a noise-free identification";
  if (c.seeds) md << " and " << c.seeds << " with Gaussian noise of " << 100.0 * c.noise_relative << " % of each sensor's RMS";
  md << "). Each point's truth is the Simbody chain, noise-free; docs/theory.md §11.6.\n\n";
  const CaseRows cr = case_rows(c, results);
  const int failed = cr.failed, converged = cr.converged;
  const auto& failures = cr.failures;
  md << "**Cases:** " << c.cases.size() - static_cast<std::size_t>(failed) << " of " << c.cases.size() << " ran; "
     << converged << " converged (optimiser converged and the fit test passed, docs/theory.md §7.6)"
     << (failed ? "; **" + std::to_string(failed) + " failed** (listed at the end)" : std::string()) << ".\n\n";

  const PointRows pr = point_rows(c, results);
  md << "## Points\n\nref: the noise-free identification on the point's truth (its error is the model error: chain "
        "lumping, mismatch). Over the seeds (every draw, converged or not; the statistics of the estimates over "
        "those with a finite reported std, `seeds_with_std`; scatter-based figures need two): the scatter of the "
        "estimates against the mean reported std (1 if the std is right), the noise-induced bias of the mean from "
        "ref in std of the mean, the share of seeds within 1.96 reported std of ref (0.95 if the std is right), and "
        "the share whose reported interval covers the truth (a draw that flags the parameter not identifiable "
        "counts as not covered).\n\n"
     << pr.points.markdown() << "\n";

  std::string hist, gp;
  if (!pr.name_order.empty() && c.seeds) {
    std::tie(hist, gp) = z_histogram(pr);
    md << "## Normalised scatter\n\n(estimate − ref) / reported std over every point's draws, per parameter, against "
          "the standard normal's counts.\n\n![histogram of (estimate - ref) / std](histogram.png)\n\n";
  }
  if (!failures.empty()) {
    md << "## Failed cases\n\n";
    for (const auto& f : failures) md << "- " << f << "\n";
  }
  md << "\nFiles: cases.csv (one row per case and parameter), points.csv (the table above), histogram.csv, "
        "histogram.gp, campaign.json; per-case results in cases/; timings (which rank ran what, how long) in "
        "timing.json, kept out of the report so that the report depends only on the results.\n";
  files["report.md"] = md.str();
  files["cases.csv"] = cr.cases.csv();
  files["points.csv"] = pr.points.csv();
  if (c.seeds && !pr.name_order.empty()) {
    files["histogram.csv"] = hist;
    files["histogram.gp"] = gp;
  }
  json cj{{"campaign", c.name}, {"points", c.points.size()}, {"cases", c.cases.size()}, {"failed", failed},
          {"converged", converged}, {"failures", failures}, {"summary", pr.summary}};
  files["campaign.json"] = cj.dump(2) + "\n";
  return files;
}

}  // namespace scoleid::crosscheck
