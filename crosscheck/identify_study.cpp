#include "scoleid/crosscheck/identify_study.h"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "scoleid/crosscheck/richardson.h"
#include "scoleid/identify.h"
#include "scoleid/io/error.h"
#include "scoleid/io/limits.h"

namespace scoleid::crosscheck {

bool IdentifyStudyOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) { if (why) *why = m; return false; };
  if (segments < 0 || segments == 1 || segments > io::limits::kMaxSegments) return fail("segments must be in [2, " + std::to_string(io::limits::kMaxSegments) + "] (0 = the scenario's)");
  if (levels < 1 || levels > 4) return fail("levels must be in [1, 4]");
  return true;
}

bool ParameterStudy::covered(std::size_t level) const {
  const double s = std[level];
  return std::isfinite(s) && std::abs(estimate[level] - truth) <= 2.0 * s;
}

bool ParameterStudy::interval_covered(std::size_t level) const {
  const double h = half_width[level];
  return std::isfinite(h) && std::abs(estimate[level] - truth) <= h;
}

bool IdentifyStudy::all_converged() const {
  for (const auto& r : runs)
    if (!r.converged) return false;
  return fe_run.termination.empty() || fe_run.converged;
}

namespace {
LevelRun run_one(std::shared_ptr<identify::Problem> p, int segments, identify::RunResult& result) {
  result = scoleid::identify_parameters(std::move(p), IdentifyOptions{}).result();
  LevelRun r;
  r.segments = segments;
  r.converged = result.converged();
  r.iterations = result.summary.iterations_done;
  r.iterations_all_attempts = result.iterations_all_attempts();
  r.termination = identify::to_string(result.summary.termination);
  r.seconds = result.wall_seconds;
  return r;
}
}  // namespace

IdentifyStudy identify_study(const io::Scenario& scenario, const IdentifyStudyOptions& opt, const std::string& truth_root,
                             const std::vector<TruthLevel>& reuse) {
  std::string why;
  if (!opt.IsValid(&why)) throw io::InputError("identify: " + why);
  if (scenario.identification.integrator != io::Integrator::Esdirk)
    io::fail_field(scenario.source, "identification.integrator",
                   "must be 'esdirk' inside scole-crosscheck: Simbody's bundled CPODES exports the same N_Vector "
                   "functions as SUNDIALS, so SUNDIALS-based integrators cannot share its process (run scole-truth and "
                   "scole-identify separately for them)",
                   io::quoted(scenario.identification.integrator));
  const auto t0 = std::chrono::steady_clock::now();
  IdentifyStudy st;
  st.scenario = scenario.name;
  st.model = io::to_string(scenario.identification.model);
  st.data_kind = opt.with_noise ? "Simbody truth with the scenario's sensor noise" : "Simbody truth, noise-free";
  st.segments = refinement(opt.segments > 0 ? opt.segments : scenario.truth.segments, opt.levels,
                           io::limits::kMaxSegments, "segments");
  bool same = !reuse.empty() && !opt.with_noise && reuse.size() == st.segments.size();
  for (std::size_t l = 0; same && l < reuse.size(); ++l) same = reuse[l].segments == st.segments[l];
  st.truths = same ? reuse : run_truth_levels(scenario, st.segments, truth_root, !opt.with_noise, opt.progress);
  for (std::size_t l = 0; l < st.truths.size(); ++l) {
    if (opt.progress) std::fprintf(stderr, "scole-crosscheck: identifying from the %d-segment truth\n", st.segments[l]);
    io::Scenario sc = scenario;
    sc.identification.band_mode = io::IdentificationSpec::BandMode::None;  // each level fitted whole, as the FE run below
    std::shared_ptr<identify::Problem> p = identify::make_problem(sc, st.truths[l].csv);
    identify::RunResult res;
    st.runs.push_back(run_one(p, st.segments[l], res));
    if (l == 0)
      for (const auto& name : res.names) {
        ParameterStudy ps;
        ps.name = name;
        const auto it = p->true_values.find(name);
        if (it == p->true_values.end())
          throw io::InputError("truth file '" + st.truths[l].csv + "': no true value for parameter '" + name + "'");
        ps.truth = it->second;
        st.parameters.push_back(ps);
      }
    for (std::size_t i = 0; i < st.parameters.size(); ++i) {
      const auto ii = static_cast<Eigen::Index>(i);
      st.parameters[i].estimate.push_back(res.estimate[ii]);
      st.parameters[i].std.push_back(res.ident.std.size() > ii ? res.ident.std[ii] : ParameterStudy::nan);
      const bool ok = res.ident.identifiable.size() > i && res.ident.identifiable[i];
      st.parameters[i].flagged.push_back(res.ident.identifiable.size() > i && !res.ident.identifiable[i]);
      st.parameters[i].half_width.push_back(ok && res.interval.half_width.size() > ii ? res.interval.half_width[ii]
                                                                                      : ParameterStudy::nan);
    }
  }
  for (auto& ps : st.parameters) {
    const auto L = ps.estimate.size();
    if (L >= 2) ps.extrapolated = richardson(ps.estimate[L - 2], ps.estimate[L - 1], 2.0, 2.0);
    if (L >= 3)
      ps.rate = observed_order(ps.estimate[L - 3], ps.estimate[L - 2], ps.estimate[L - 1], 2.0, 1e-12 * std::abs(ps.truth));
  }
  if (opt.fe_on_fe) {
    if (opt.progress) std::fprintf(stderr, "scole-crosscheck: identifying from synthetic FE data (inverse crime)\n");
    io::Scenario sc = scenario;
    if (!opt.with_noise)
      for (auto& s : sc.sensors) s.noise_std = 0.0;
    identify::RunResult res;
    st.fe_run = run_one(identify::make_problem(sc, std::nullopt), 0, res);
    for (std::size_t i = 0; i < st.parameters.size(); ++i) {
      const auto ii = static_cast<Eigen::Index>(i);
      st.parameters[i].fe_on_fe = res.estimate[ii];
      st.parameters[i].fe_on_fe_std = res.ident.std.size() > ii ? res.ident.std[ii] : ParameterStudy::nan;
    }
  }
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return st;
}

Table identify_table(const IdentifyStudy& s) {
  Table t;
  t.title = "Identification, " + s.scenario + " (" + s.data_kind + ", " + s.model +
            " model): relative errors against the truth's values, %";
  t.header = {"parameter", "truth"};
  for (int n : s.segments) t.header.push_back("n=" + std::to_string(n));
  t.header.push_back("extrapolated");
  t.header.push_back("rate");
  t.header.push_back("FE-on-FE");
  t.header.push_back("2 std n=" + std::to_string(s.segments.front()));
  t.header.push_back("covered");
  t.header.push_back("± interval");
  t.header.push_back("covered");
  for (const auto& p : s.parameters) {
    std::vector<std::string> row{p.name, number(p.truth, 7)};
    for (std::size_t l = 0; l < p.estimate.size(); ++l) row.push_back(percent(p.error(l), 3));
    row.push_back(percent(p.extrapolated_error(), 3));
    row.push_back(number(p.rate, 3));
    row.push_back(percent(p.fe_on_fe_error(), 3));
    row.push_back(percent(2.0 * p.std.front() / std::abs(p.truth), 3));
    row.push_back(std::isfinite(p.std.front()) ? (p.covered(0) ? "yes" : "no") : "no std");
    row.push_back(percent(p.half_width.front() / std::abs(p.truth), 3));
    // No interval: the parameter is flagged, or the run gave a std without an interval (the
    // nonlinear model), or none at all (--no-std).
    row.push_back(std::isfinite(p.half_width.front()) ? (p.interval_covered(0) ? "yes" : "no")
                  : !p.flagged.empty() && p.flagged.front() ? "flagged"
                  : std::isfinite(p.std.front())            ? "no interval"
                                                            : "not assessed");
    t.rows.push_back(row);
  }
  return t;
}

nlohmann::json to_json(const IdentifyStudy& s) {
  const auto num = json_number;
  auto nums = [&](const std::vector<double>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (double x : v) a.push_back(num(x));
    return a;
  };
  auto run = [](const LevelRun& r) {
    return nlohmann::json{{"segments", r.segments}, {"converged", r.converged}, {"iterations", r.iterations}, {"iterations_all_attempts", r.iterations_all_attempts},
                          {"termination", r.termination}, {"seconds", r.seconds}};
  };
  nlohmann::json j;
  j["scenario"] = s.scenario;
  j["model"] = s.model;
  j["data"] = s.data_kind;
  j["segments"] = s.segments;
  j["all_converged"] = s.all_converged();
  j["parameters"] = nlohmann::json::array();
  for (const auto& p : s.parameters) {
    nlohmann::json e;
    e["name"] = p.name;
    e["truth"] = num(p.truth);
    e["estimate"] = nums(p.estimate);
    e["std"] = nums(p.std);
    std::vector<double> err;
    nlohmann::json cov = nlohmann::json::array(), icov = nlohmann::json::array();
    for (std::size_t l = 0; l < p.estimate.size(); ++l) {
      err.push_back(p.error(l));
      cov.push_back(p.covered(l));
      icov.push_back(p.interval_covered(l));
    }
    e["half_width"] = nums(p.half_width);
    e["covered_by_interval"] = icov;
    e["relative_error"] = nums(err);
    e["covered_by_2std"] = cov;
    e["extrapolated"] = num(p.extrapolated);
    e["extrapolated_relative_error"] = num(p.extrapolated_error());
    e["observed_rate"] = num(p.rate);
    e["fe_on_fe"] = num(p.fe_on_fe);
    e["fe_on_fe_relative_error"] = num(p.fe_on_fe_error());
    e["fe_on_fe_std"] = num(p.fe_on_fe_std);
    j["parameters"].push_back(e);
  }
  j["runs"] = nlohmann::json::array();
  for (const auto& r : s.runs) j["runs"].push_back(run(r));
  j["fe_on_fe_run"] = run(s.fe_run);
  nlohmann::json tr = nlohmann::json::array();
  for (const auto& l : s.truths)
    tr.push_back({{"segments", l.segments}, {"file", "truths/n" + std::to_string(l.segments) + "/truth.csv"}, {"seconds", l.seconds}});
  j["truths"] = tr;
  j["seconds"] = s.seconds;
  return j;
}

}  // namespace scoleid::crosscheck
