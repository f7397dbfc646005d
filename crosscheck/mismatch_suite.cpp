#include "scoleid/crosscheck/mismatch_suite.h"

#include "scoleid/crosscheck/json_shape.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "scoleid/crosscheck/case_identification.h"
#include "scoleid/crosscheck/richardson.h"
#include "scoleid/crosscheck/scenario_overlay.h"
#include "study_yaml.h"
#include "scoleid/crosscheck/table.h"
#include "scoleid/crosscheck/truth_levels.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/io/error.h"
#include "scoleid/io/input_file.h"
#include "scoleid/io/validation.h"

namespace scoleid::crosscheck {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using study::bad;
using study::number_of;
using study::text_of;

std::pair<double, double> range_of(const YAML::Node& n, const std::string& file, const std::string& field) {
  if (!n.IsSequence() || n.size() != 2) bad(file, field, "must be [low, high]", text_of(n));
  const double lo = number_of(n[0], file, field + "[0]"), hi = number_of(n[1], file, field + "[1]");
  if (!(lo < hi)) bad(file, field, "needs low < high", text_of(n));
  return {lo, hi};
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

json num(double v) { return json_number(v); }

// A number of the results, NaN where it was not finite (written as null).
double val(const json& v) { return v.is_number() ? v.get<double>() : std::nan(""); }

json check(const std::string& what, bool held, const std::string& measured) {
  return json{{"what", what}, {"held", held}, {"measured", measured}};
}

std::string fmt(const char* f, double a, double b = 0.0) {
  char buf[128];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}

}  // namespace

std::vector<std::string> suite_files(const std::string& dir) {
  std::vector<std::string> v;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().extension() == ".yaml") v.push_back(e.path().string());
  if (ec) throw io::InputError("suite directory '" + dir + "': " + ec.message());
  std::sort(v.begin(), v.end());
  return v;
}

static SuiteFile load_suite_file_checked(const std::string& path);

SuiteFile load_suite_file(const std::string& path) {
  try {
    return load_suite_file_checked(path);
  } catch (const YAML::Exception& e) {
    throw io::InputError("suite file '" + path + "': " + e.msg + " (line " + std::to_string(e.mark.line + 1) + ")");
  }
}

static SuiteFile load_suite_file_checked(const std::string& path) {
  SuiteFile f;
  f.path = path;
  YAML::Node root;
  try {
    const std::string text = io::read_text_file(path, "suite file");
    io::check_yaml_nesting(text, "suite file '" + path + "'");
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw io::InputError("suite file '" + path + "': malformed YAML: " + e.msg);
  }
  io::check_yaml_document(root, "suite file '" + path + "'", true);
  if (!root.IsMap()) bad(path, "(top level)", "must be a map", "");
  static const std::vector<std::string> known = {"family", "mismatch", "size_unit", "reason", "scenario",
                                                 "overlay", "cases", "noise", "expect"};
  for (const auto& kv : root) {
    const std::string k = kv.first.as<std::string>();
    if (std::find(known.begin(), known.end(), k) == known.end()) bad(path, k, "is not a suite field", "'" + k + "'");
  }
  auto str = [&](const char* key, bool required) {
    const YAML::Node n = root[key];
    if (!n) {
      if (required) bad(path, key, "is required", "none");
      return std::string();
    }
    if (!n.IsScalar()) bad(path, key, "must be text", text_of(n));
    return n.Scalar();
  };
  f.family = str("family", true);
  if (f.family.empty()) bad(path, "family", "must not be empty (it names files)", "''");
  for (char c : f.family)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_'))
      bad(path, "family", "must be letters, digits, - and _ (it names files)", "'" + f.family + "'");
  f.mismatch = str("mismatch", true);
  f.size_unit = str("size_unit", false);
  f.reason = str("reason", true);
  f.base = str("scenario", true);
  if (root["overlay"]) {
    if (!root["overlay"].IsMap()) bad(path, "overlay", "must be a map of scenario fields", text_of(root["overlay"]));
    f.overlay = text_of(root["overlay"]);
  }
  const YAML::Node cases = root["cases"];
  if (!cases || !cases.IsSequence() || cases.size() == 0) bad(path, "cases", "must be a non-empty list", cases ? text_of(cases) : "none");
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string field = "cases[" + std::to_string(i) + "]";
    const YAML::Node c = cases[i];
    if (!c.IsMap()) bad(path, field, "must be a map {label, size, overlay}", text_of(c));
    SuiteCase sc;
    if (!c["label"] || !c["label"].IsScalar()) bad(path, field + ".label", "is required", "none");
    sc.label = c["label"].Scalar();
    for (char ch : sc.label)
      if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_' || ch == '.'))
        bad(path, field + ".label", "must be letters, digits, '.', - and _ (it names a directory)", "'" + sc.label + "'");
    for (const auto& o : f.cases)
      if (o.label == sc.label) bad(path, field + ".label", "is used twice", "'" + sc.label + "'");
    if (!c["size"]) bad(path, field + ".size", "is required", "none");
    sc.size = number_of(c["size"], path, field + ".size");
    if (c["overlay"]) {
      if (!c["overlay"].IsMap()) bad(path, field + ".overlay", "must be a map of scenario fields", text_of(c["overlay"]));
      sc.overlay = text_of(c["overlay"]);
    }
    f.cases.push_back(sc);
  }
  if (const YAML::Node n = root["noise"]) {
    if (!n.IsMap() || !n["relative"] || !n["seeds"]) bad(path, "noise", "must be {relative: r, seeds: K, seed: first}", text_of(n));
    f.noise_relative = number_of(n["relative"], path, "noise.relative");
    if (!(f.noise_relative > 0 && f.noise_relative < 1)) bad(path, "noise.relative", "must be in (0, 1)", n["relative"].Scalar());
    const double s = number_of(n["seeds"], path, "noise.seeds");
    if (!(s >= 2 && s <= 1000 && s == std::floor(s))) bad(path, "noise.seeds", "must be an integer in [2, 1000]", n["seeds"].Scalar());
    f.seeds = static_cast<int>(s);
    if (n["seed"]) {
      const double b = number_of(n["seed"], path, "noise.seed");
      if (!(b >= 0 && b < 4294967296.0 && b == std::floor(b))) bad(path, "noise.seed", "must be an integer in [0, 2^32)", n["seed"].Scalar());
      f.noise_seed = static_cast<unsigned>(b);
    }
  }
  if (const YAML::Node e = root["expect"]) {
    if (!e.IsMap()) bad(path, "expect", "must be a map", text_of(e));
    for (const auto& kv : e) {
      const std::string k = kv.first.as<std::string>(), field = "expect." + k;
      const YAML::Node v = kv.second;
      if (k == "max_relative_error") {
        if (!v.IsMap()) bad(path, field, "must be a map parameter: bound", text_of(v));
        for (const auto& pv : v) {
          const std::string pn = pv.first.as<std::string>();
          const double b = number_of(pv.second, path, field + "." + pn);
          if (!(b > 0)) bad(path, field + "." + pn, "must be > 0", pv.second.Scalar());
          f.expect.max_relative_error[pn] = b;
        }
      } else if (k == "flagged") {
        if (!v.IsSequence()) bad(path, field, "must be a list of parameter names", text_of(v));
        for (const auto& x : v) f.expect.flagged.push_back(x.as<std::string>());
      } else if (k == "all_covered") {
        if (!v.IsScalar() || (v.Scalar() != "true" && v.Scalar() != "false")) bad(path, field, "must be true or false", text_of(v));
        f.expect.all_covered = v.Scalar() == "true";
      } else if (k == "rate") {
        if (v.IsMap())
          for (const auto& pv : v) f.expect.rate[pv.first.as<std::string>()] = range_of(pv.second, path, field + "." + pv.first.as<std::string>());
        else
          f.expect.rate[""] = range_of(v, path, field);
      } else if (k == "scatter_over_crb") {
        f.expect.scatter_over_crb = range_of(v, path, field);
      } else if (k == "noise_bias_sigmas") {
        f.expect.noise_bias_sigmas = number_of(v, path, field);
      } else {
        bad(path, field, "is not an expectation (max_relative_error, flagged, all_covered, rate, scatter_over_crb, noise_bias_sigmas)", "'" + k + "'");
      }
    }
  }
  if (f.expect.scatter_over_crb && f.seeds == 0) bad(path, "expect.scatter_over_crb", "needs a noise section", "");
  return f;
}

io::Scenario case_scenario(const SuiteFile& f, std::size_t k) {
  const SuiteCase& c = f.cases.at(k);
  const std::string yaml = overlaid_scenario_yaml(f.base, f.path, "scenario", {f.overlay, c.overlay});
  return checked_scenario(yaml, f.path + " (case '" + c.label + "' on '" + f.base + "')");
}

namespace {

// Over a case's noise seeds, per parameter: mean, scatter against the mean Cramér–Rao std, the
// noise-induced bias from the noise-free estimate (and against the truth) in std of the mean, the
// interval coverage and the converged runs.
json seed_statistics(const json& runs, const json& row) {
  json stats = json::array();
  for (std::size_t i = 0; i < row["parameters"].size(); ++i) {
    std::vector<double> est, crb;
    int covered = 0, conv = 0;
    for (const auto& r : runs) {
      est.push_back(val(r["parameters"][i]["estimate"]));
      crb.push_back(val(r["parameters"][i]["std"]));
      covered += r["parameters"][i]["covered"].get<bool>() ? 1 : 0;
      conv += r["converged"].get<bool>() ? 1 : 0;
    }
    double mean = 0, var = 0;
    for (double e : est) mean += e / static_cast<double>(est.size());
    for (double e : est) var += (e - mean) * (e - mean) / static_cast<double>(est.size() - 1);
    double crb_mean = 0;
    for (double s : crb) crb_mean += s / static_cast<double>(crb.size());
    const double scatter = std::sqrt(var), ref = val(row["noise_free"][i]["estimate"]);
    const double truth = val(row["noise_free"][i]["truth"]);
    const double std_of_mean = scatter / std::sqrt(static_cast<double>(est.size()));
    stats.push_back({{"name", row["parameters"][i]["name"]},
                     {"mean", num(mean)},
                     {"scatter", num(scatter)},
                     {"crb_std", num(crb_mean)},
                     {"scatter_over_crb", num(scatter / crb_mean)},
                     {"noise_free_estimate", num(ref)},
                     {"bias_from_noise", num(mean - ref)},
                     {"bias_in_std_of_mean", num(std::abs(mean - ref) / std_of_mean)},
                     // against the truth's value: the noise-free estimate's own (model) error included
                     {"mean_minus_truth_in_std_of_mean", num((mean - truth) / std_of_mean)},
                     {"interval_coverage", static_cast<double>(covered) / static_cast<double>(runs.size())},
                     {"converged_runs", conv}});
  }
  return stats;
}

// One case of a family: its truth, the noise-free identification and, with seeds, one per draw.
json suite_case(const SuiteFile& f, std::size_t k, const std::string& out, const SuiteOptions& opt, int seeds) {
  const SuiteCase& c = f.cases[k];
  const io::Scenario sc = case_scenario(f, k);
  if (opt.progress) std::fprintf(stderr, "scole-crosscheck suite: %s, case %s: truth (%d segments)\n", f.family.c_str(), c.label.c_str(), sc.truth.segments);
  const auto truths = run_truth_levels(sc, {sc.truth.segments}, (fs::path(out) / "truths" / f.family / c.label).string(),
                                       true, false);
  if (opt.progress) std::fprintf(stderr, "scole-crosscheck suite: %s, case %s: identifying\n", f.family.c_str(), c.label.c_str());
  // The truth is noise-free: the identifier is told no noise level it does not have.
  io::Scenario id_sc = sc;
  for (auto& s : id_sc.sensors) s.noise_std = 0.0;
  id_sc.identification.band_mode = io::IdentificationSpec::BandMode::None;  // (the noise added below comes after any band)
  auto p = identify::make_problem(id_sc, truths.front().csv);
  json row = identify_row(std::move(p));
  row["label"] = c.label;
  row["size"] = c.size;
  row["truth_seconds"] = truths.front().seconds;
  if (seeds) {
    // The noise-free row above is the reference; each seed adds noise to the same truth.
    row["noise_free"] = row["parameters"];
    json runs = json::array();
    for (int s = 0; s < seeds; ++s) {
      auto ps = identify::make_problem(id_sc, truths.front().csv);
      add_noise(*ps, f.noise_relative, f.noise_seed + 1000003u * static_cast<unsigned>(k) + static_cast<unsigned>(s));
      runs.push_back(identify_row(std::move(ps)));
      if (opt.progress && (s + 1) % 5 == 0)
        std::fprintf(stderr, "scole-crosscheck suite: %s, case %s: %d of %d seeds\n", f.family.c_str(), c.label.c_str(), s + 1, seeds);
    }
    // The case's row is the first seed's; the seeds' statistics beside it.
    row["parameters"] = runs.front()["parameters"];
    int converged = row["converged"].get<bool>() ? 1 : 0;  // the noise-free reference
    for (const auto& r : runs) converged += r["converged"].get<bool>() ? 1 : 0;
    row["converged"] = converged == seeds + 1;
    row["termination"] = std::to_string(converged) + " of " + std::to_string(seeds + 1) + " runs converged (noise-free and every draw)";
    row["seed_statistics"] = seed_statistics(runs, row);
    row["seeds"] = runs;
  }
  return row;
}

// The progress line of a finished case: each parameter's error and interval.
void print_case(const SuiteFile& f, const SuiteCase& c, const json& row) {
  std::string line;
  for (const auto& q : row["parameters"])
    line += " " + q["name"].get<std::string>() + " " + fmt("%+.2e", q["relative_error"].is_number() ? q["relative_error"].get<double>() : std::nan("")) +
            (!q["identifiable"].get<bool>() ? std::string(" NOT IDENTIFIABLE")
             : !q["relative_half_width"].is_number()
                 ? std::string(" (no interval)")
                 : " ±" + fmt("%.2e", q["relative_half_width"].get<double>()) + (q["covered"].get<bool>() ? " covered" : " NOT covered"));
  std::fprintf(stderr, "scole-crosscheck suite: %s, case %s:%s\n", f.family.c_str(), c.label.c_str(), line.c_str());
}

// A case's expectations: the optimiser converged, the flags, the error bounds, the coverage, and
// with seeds the scatter against the Cramér–Rao std and the noise bias.
void case_checks(const SuiteFile& f, const json& c, json& checks) {
  const std::string at = " (case " + c["label"].get<std::string>() + ")";
  // The optimiser must converge; whether the model then explains the data (the fit test) is what
  // the family measures, reported beside the errors, not an expectation.
  checks.push_back(check("the optimiser converged" + at, c["optimizer_converged"].get<bool>(), c["termination"].get<std::string>()));
  for (const auto& q : c["parameters"]) {
    const std::string n = q["name"];
    const bool expect_flag = std::find(f.expect.flagged.begin(), f.expect.flagged.end(), n) != f.expect.flagged.end();
    const bool flagged = !q["identifiable"].get<bool>();
    checks.push_back(check(n + (expect_flag ? " is flagged not identifiable" : " is identifiable") + at, flagged == expect_flag,
                           flagged ? q.value("not_identifiable_because", std::string("flagged")) : "identifiable"));
    const auto b = f.expect.max_relative_error.find(n);
    if (b != f.expect.max_relative_error.end() && !flagged) {
      const double e = q["relative_error"].is_number() ? std::abs(q["relative_error"].get<double>()) : INFINITY;
      checks.push_back(check(n + " relative error <= " + fmt("%.3g", b->second) + at, e <= b->second, fmt("%.3e", e)));
    }
    if (f.expect.all_covered && !flagged)
      checks.push_back(check(n + " interval covers the truth" + at, q["covered"].get<bool>(),
                             fmt("error %.3e, half-width %.3e", std::abs(val(q["relative_error"])), val(q["relative_half_width"]))));
  }
  if (c.contains("seed_statistics"))
    for (const auto& s : c["seed_statistics"]) {
      const std::string n = s["name"];
      const double r = s["scatter_over_crb"].is_number() ? s["scatter_over_crb"].get<double>() : std::nan("");
      if (f.expect.scatter_over_crb)
        checks.push_back(check(n + " seed scatter / Cramér–Rao std in [" + fmt("%.3g", f.expect.scatter_over_crb->first) + ", " +
                                   fmt("%.3g", f.expect.scatter_over_crb->second) + "]" + at,
                               r >= f.expect.scatter_over_crb->first && r <= f.expect.scatter_over_crb->second, fmt("%.3f", r)));
      const double bs = s["bias_in_std_of_mean"].is_number() ? s["bias_in_std_of_mean"].get<double>() : std::nan("");
      checks.push_back(check(n + " noise-induced bias within " + fmt("%.3g", f.expect.noise_bias_sigmas) + " std of the mean" + at,
                             bs <= f.expect.noise_bias_sigmas, fmt("%.2f std", bs)));
    }
}

// The observed order of each parameter's estimate against the family's band. With three or more
// cases in geometric progression of size it is the self-convergence order (richardson.h) of
// consecutive triples: the differences between cases, so an n-independent floor the family does
// not vary (the truth's geometric nonlinearity, say) neither hides nor fakes the rate, and the
// Richardson limit from the two finest cases is reported; with two cases, the order of the error.
void rate_checks(const SuiteFile& f, json& res, json& checks) {
  if (f.expect.rate.empty() || res["cases"].size() < 2) return;
  const auto& cs = res["cases"];
  const std::size_t m = cs.size();
  auto size = [&](std::size_t k) { return cs[k]["size"].get<double>(); };
  bool geometric = m >= 3;
  for (std::size_t k = 0; geometric && k + 2 < m; ++k)
    geometric = std::abs(size(k + 2) / size(k + 1) - size(k + 1) / size(k)) <= 1e-9 * (size(k + 1) / size(k));
  bool rated = false;
  for (std::size_t i = 0; i < cs[0]["parameters"].size(); ++i) {
    const std::string n = cs[0]["parameters"][i]["name"];
    auto band = f.expect.rate.find(n);
    if (band == f.expect.rate.end()) band = f.expect.rate.find("");
    if (band == f.expect.rate.end()) continue;
    const std::pair<double, double> range = band->second;
    rated = true;
    auto err = [&](std::size_t k) { return val(cs[k]["parameters"][i]["relative_error"]); };
    json orders = json::array();
    bool ok = true;
    std::string measured;
    auto add = [&](double order) {
      orders.push_back(num(order));
      ok = ok && order >= range.first && order <= range.second;  // false for NaN
      measured += (measured.empty() ? "" : ", ") + fmt("%.2f", order);
    };
    if (geometric) {
      double last = std::nan("");
      for (std::size_t k = 0; k + 2 < m; ++k) add(last = observed_order(err(k), err(k + 1), err(k + 2), size(k + 1) / size(k)));
      const double p = std::isfinite(last) ? last : 0.5 * (range.first + range.second);
      res["richardson_limit_error"][n] = num(richardson(err(m - 2), err(m - 1), size(m - 1) / size(m - 2), p));
    } else {
      for (std::size_t k = 0; k + 1 < m; ++k)
        add(std::log(std::abs(err(k)) / std::abs(err(k + 1))) / std::log(size(k + 1) / size(k)));
    }
    res["observed_orders"][n] = orders;
    checks.push_back(check(n + (geometric ? " estimate converges" : " error falls") + " at order in [" +
                               fmt("%.3g", range.first) + ", " + fmt("%.3g", range.second) + "]",
                           ok, measured));
  }
  if (rated) res["order_kind"] = geometric ? "self-convergence" : "error";
}

// Every parameter an expectation names must be one the family estimates (a misspelt name would
// otherwise check nothing).
void name_checks(const SuiteFile& f, const json& res, json& checks) {
  if (!res["cases"].empty()) {
    std::vector<std::string> names;
    for (const auto& q : res["cases"][0]["parameters"]) names.push_back(q["name"].get<std::string>());
    auto known = [&](const std::string& n) { return n.empty() || std::find(names.begin(), names.end(), n) != names.end(); };
    std::vector<std::string> named;
    for (const auto& [n, b] : f.expect.max_relative_error) named.push_back(n);
    for (const auto& [n, r] : f.expect.rate) named.push_back(n);
    for (const auto& n : f.expect.flagged) named.push_back(n);
    for (const auto& n : named)
      if (!known(n)) checks.push_back(check("expectation names an estimated parameter", false, "'" + n + "' is not estimated"));
  }
}

}  // namespace

json run_suite_file(const SuiteFile& f, const std::string& out, const SuiteOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const int seeds = f.seeds > 0 ? (opt.seeds > 0 ? opt.seeds : f.seeds) : 0;
  json res{{"family", f.family}, {"mismatch", f.mismatch}, {"size_unit", f.size_unit}, {"reason", f.reason},
           {"scenario", f.base}, {"file", fs::path(f.path).filename().string()}};
  if (seeds) res["noise"] = {{"relative", f.noise_relative}, {"seeds", seeds}};
  res["cases"] = json::array();
  for (std::size_t k = 0; k < f.cases.size(); ++k) {
    res["cases"].push_back(suite_case(f, k, out, opt, seeds));
    if (opt.progress) print_case(f, f.cases[k], res["cases"].back());
  }
  json checks = json::array();
  for (const auto& c : res["cases"]) case_checks(f, c, checks);
  rate_checks(f, res, checks);
  name_checks(f, res, checks);
  bool all = true;
  for (const auto& c : checks) all = all && c["held"].get<bool>();
  res["checks"] = checks;
  res["expectations_met"] = all;
  res["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

void check_suite_result(const json& f, const std::string& file) {
  const Shape s(file);
  if (!f.is_object()) s.fail("(top level)", "an object", &f);
  for (const char* key : {"family", "mismatch", "size_unit", "reason"}) s.text(f, key, "");
  s.optional(f, "expectations_met", [&] { s.flag(f, "expectations_met", ""); });
  s.optional(f, "checks", [&] {
    s.each(f, "checks", "", [&](const json& check, const std::string& w) {
      s.flag(check, "held", w);
      s.text(check, "what", w);
      s.text(check, "measured", w);
    });
  });
  if (!f.value("expectations_met", false) && !f.contains("checks")) s.fail("checks", "present when expectations_met is not true", nullptr);
  s.each(f, "cases", "", [&](const json& c, const std::string& w) {
    s.text(c, "label", w);
    s.number(c, "size", w);
    if (!c.at("size").is_number()) s.fail(w + "size", "a number", &c.at("size"));
    s.optional(c, "explains_data", [&] { s.flag(c, "explains_data", w); });
    s.optional(c, "fit_ratio", [&] { s.number(c, "fit_ratio", w); });
    s.optional(c, "seeds", [&] {
      if (!c.at("seeds").is_array()) s.fail(w + "seeds", "an array", &c.at("seeds"));
    });
    s.optional(c, "seed_statistics", [&] {
      if (!c.contains("seeds")) s.fail(w + "seeds", "present with seed_statistics", nullptr);
      s.each(c, "seed_statistics", w, [&](const json& st, const std::string& sw) { s.text(st, "name", sw); });
    });
    s.each(c, "parameters", w, [&](const json& q, const std::string& pw) {
      s.text(q, "name", pw);
      s.flag(q, "identifiable", pw);
      s.flag(q, "covered", pw);
      for (const char* key : {"truth", "estimate", "relative_error", "relative_half_width"}) s.number(q, key, pw);
    });
  });
}

SuiteSummary summarise_suite(const std::vector<json>& families) {
  SuiteSummary s;
  std::vector<double> widths, errors;
  for (const auto& f : families) {
    if (!f.value("expectations_met", false)) {
      s.expectations_met = false;
      for (const auto& c : f["checks"])
        if (!c["held"].get<bool>())
          s.failures.push_back(f["family"].get<std::string>() + ": " + c["what"].get<std::string>() + ": " + c["measured"].get<std::string>());
    }
    for (const auto& c : f["cases"])
      for (const auto& q : c["parameters"]) {
        // Coverage is counted where an interval was given (a flagged parameter has none, nor
        // does the nonlinear model's).
        if (!q["identifiable"].get<bool>() || !q["relative_half_width"].is_number()) continue;
        ++s.cases;
        s.covered += q["covered"].get<bool>() ? 1 : 0;
        widths.push_back(q["relative_half_width"].get<double>());
        errors.push_back(q["relative_error"].is_number() ? std::abs(q["relative_error"].get<double>()) : INFINITY);  // diverged: no bound
      }
  }
  s.coverage = s.cases ? static_cast<double>(s.covered) / s.cases : std::nan("");
  s.median_relative_half_width = median(widths);
  s.median_relative_error = median(errors);
  s.sharpness = s.median_relative_half_width / s.median_relative_error;
  return s;
}

std::map<std::string, std::string> suite_report(const std::vector<json>& families, const SuiteSummary& s) {
  std::map<std::string, std::string> files;
  // suite.csv and the data blocks of the plot.
  std::string csv =
      "family,case,size,size_unit,parameter,truth,estimate,relative_error,relative_half_width,covered,identifiable,explains_data\n";
  std::ostringstream md;
  md << "# Mismatch suite\n\n"
     << "Identification on the Simbody truth when the truth differs from the identifier's model, one family per row "
        "group (crosscheck/mismatch/*.yaml; docs/theory.md §11.5). Errors are relative to the truth's values; the "
        "interval is the one identify.json reports (±half-width: noise, visible residual, half-record shift, declared "
        "uncertainties; docs/theory.md §8.2).\n\n";
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "**Coverage:** the truth lies inside the reported interval in %d of %d estimates (%.1f %%; target >= 90 %%).  \n"
                "**Sharpness:** median relative half-width %.3g against median relative error %.3g: ratio %.2f (target <= 10).  \n",
                s.covered, s.cases, 100.0 * s.coverage, s.median_relative_half_width, s.median_relative_error, s.sharpness);
  md << buf;
  md << "**Expectations of the suite files:** " << (s.expectations_met ? "all held" : "NOT all held") << ".\n\n";
  for (const auto& f : s.failures) md << "- failed: " << f << "\n";
  md << "\n![error and interval against mismatch size](suite.png)\n\n";
  md << "The last column is the fit test (docs/theory.md §7.6): whether the model at the estimate explains the data "
        "within noise, discretisation and the default 1 % model error — where it says no, the mismatch shows in the "
        "residual and the run exits 1 (not converged).\n\n";
  md << "| family | mismatch | case | size | parameter | error % | ± interval % | covered | explains data |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
  std::ostringstream gp;
  gp << "# Error and reported interval against mismatch size, one panel per family (gnuplot suite.gp)\n"
     << "set terminal pngcairo noenhanced size 1400," << 300 * ((families.size() + 2) / 3) << " font ',9'\nset output 'suite.png'\n"
     << "set multiplot layout " << (families.size() + 2) / 3 << ",3\nset grid\nset key top left\nset ylabel '|relative error| %'\n";
  for (const auto& f : families) {
    const std::string fam = f["family"];
    std::map<std::string, std::string> blocks;  // parameter → "size error halfwidth" lines
    for (const auto& c : f["cases"])
      for (const auto& q : c["parameters"]) {
        const bool ok = q["identifiable"].get<bool>();
        const double err = q["relative_error"].is_number() ? q["relative_error"].get<double>() : std::nan("");
        const double hw = ok && q["relative_half_width"].is_number() ? q["relative_half_width"].get<double>() : std::nan("");
        const bool explains = c.value("explains_data", true);
        std::snprintf(buf, sizeof buf, "%s,%s,%.9g,%s,%s,%.12g,%.12g,%.6e,%.6e,%s,%s,%s\n", fam.c_str(),
                      c["label"].get<std::string>().c_str(), c["size"].get<double>(), f["size_unit"].get<std::string>().c_str(),
                      q["name"].get<std::string>().c_str(), q["truth"].is_number() ? q["truth"].get<double>() : std::nan(""),
                      q["estimate"].is_number() ? q["estimate"].get<double>() : std::nan(""), err, hw,
                      q["covered"].get<bool>() ? "yes" : "no", ok ? "yes" : "no", explains ? "yes" : "no");
        csv += buf;
        const std::string fit = explains ? "yes" : "no (" + fmt("%.2g", c.contains("fit_ratio") && c["fit_ratio"].is_number() ? c["fit_ratio"].get<double>() : std::nan("")) + "x)";
        std::snprintf(buf, sizeof buf, "| %s | %s | %s | %g %s | %s | %+.4f | %s | %s | %s |\n", fam.c_str(),
                      f["mismatch"].get<std::string>().c_str(), c["label"].get<std::string>().c_str(), c["size"].get<double>(),
                      f["size_unit"].get<std::string>().c_str(), q["name"].get<std::string>().c_str(), 100.0 * err,
                      ok ? fmt("%.4f", 100.0 * hw).c_str() : "NOT IDENTIFIABLE", !ok ? "(flagged)" : q["covered"].get<bool>() ? "yes" : "**no**",
                      fit.c_str());
        md << buf;
        std::snprintf(buf, sizeof buf, "%.9g %.6e %s\n", c["size"].get<double>(), 100.0 * std::abs(err), ok ? fmt("%.6e", 100.0 * hw).c_str() : "NaN");
        blocks[q["name"].get<std::string>()] += buf;
      }
    gp << "set title '" << fam << "'\nset xlabel '" << f["size_unit"].get<std::string>() << "'\nset logscale y\n";
    std::string plot = "plot ";
    std::string data;
    int idx = 0;
    for (const auto& [name, lines] : blocks) {
      plot += std::string(idx ? ", " : "") + "'-' using 1:2 with linespoints title '" + name + " error', '-' using 1:3 with linespoints dt 2 pt 6 title '" + name + " ±interval'";
      data += lines + "e\n" + lines + "e\n";
      ++idx;
    }
    gp << plot << "\n" << data;
  }
  gp << "unset multiplot\n";
  md << "\n## Noise seeds\n\nThe noise-induced bias is the mean's distance from the noise-free estimate; the distance from the "
        "truth adds the noise-free estimate's own model error (chain lumping, nonlinearity), which averaging does not remove.\n\n"
        "| family | case | parameter | seeds | scatter / CRB std | noise bias (std of mean) | mean − truth (std of mean) | interval coverage over seeds |\n|---|---|---|---|---|---|---|---|\n";
  for (const auto& f : families)
    for (const auto& c : f["cases"])
      if (c.contains("seed_statistics"))
        for (const auto& st : c["seed_statistics"]) {
          auto val = [&](const char* k) { return st.contains(k) && st[k].is_number() ? st[k].get<double>() : std::nan(""); };
          std::snprintf(buf, sizeof buf, "| %s | %s | %s | %zu | %.3f | %.2f | %+.2f | %.2f |\n", f["family"].get<std::string>().c_str(),
                        c["label"].get<std::string>().c_str(), st["name"].get<std::string>().c_str(), c["seeds"].size(),
                        val("scatter_over_crb"), val("bias_in_std_of_mean"), val("mean_minus_truth_in_std_of_mean"),
                        val("interval_coverage"));
          md << buf;
        }
  md << "\n## Why each family's bounds are what they are\n\n";
  for (const auto& f : families)
    md << "- **" << f["family"].get<std::string>() << "** (" << f["mismatch"].get<std::string>() << "): " << f["reason"].get<std::string>() << "\n";
  files["report.md"] = md.str();
  files["suite.csv"] = csv;
  files["suite.gp"] = gp.str();
  json sj{{"cases", s.cases}, {"covered", s.covered}, {"coverage", num(s.coverage)},
          {"median_relative_half_width", num(s.median_relative_half_width)},
          {"median_relative_error", num(s.median_relative_error)}, {"sharpness", num(s.sharpness)},
          {"expectations_met", s.expectations_met}, {"failures", s.failures}, {"families", json::array()}};
  for (const auto& f : families) sj["families"].push_back(f["family"]);
  files["suite.json"] = sj.dump(2) + "\n";
  return files;
}

}  // namespace scoleid::crosscheck
