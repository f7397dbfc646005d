#include "scoleid/crosscheck/trajectories.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "scoleid/identify/fe/modal.h"
#include "scoleid/io/validation.h"
#include "scoleid/identify/fe/scole_nonlinear.h"
#include "scoleid/identify/time/nonlinear_forward.h"
#include "scoleid/identify/run/problem.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"
#include "scoleid/io/limits.h"

namespace scoleid::crosscheck {

namespace {
// The reference FE run resolves the first kResolvedModes flexible modes with ω h <= kPhaseStep:
// the ESDIRK scheme's relative phase error per step is O((ω h)³), so over the ~10³ periods of a
// record it stays near 1e-6 on those modes (the chain's differences are 1e-4 and up).
constexpr int kResolvedModes = 5;
constexpr double kPhaseStep = 0.03;
}  // namespace

bool TrajectoryOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) { if (why) *why = m; return false; };
  if (segments < 0 || segments == 1 || segments > io::limits::kMaxSegments) return fail("segments must be in [2, " + std::to_string(io::limits::kMaxSegments) + "] (0 = the scenario's)");
  if (elements < 0 || elements > io::limits::kMaxElements) return fail("elements must be in [1, " + std::to_string(io::limits::kMaxElements) + "] (0 = 4 x the identifier's)");
  if (levels < 1 || levels > 4) return fail("levels must be in [1, 4]");
  if (!(fe_step >= 0 && fe_step < 1e6)) return fail("fe_step must be >= 0 (0 = automatic)");
  if (nonlinear_elements < 0 || nonlinear_elements > io::limits::kMaxElements) return fail("nonlinear_elements must be in [1, " + std::to_string(io::limits::kMaxElements) + "] (0 = the linear comparison's)");
  return true;
}

double fe_reference_step(const identify::Problem& p) {
  const auto& names = p.params->names();
  identify::VectorXd q(static_cast<Eigen::Index>(names.size()));
  for (std::size_t i = 0; i < names.size(); ++i) q[static_cast<Eigen::Index>(i)] = p.true_values.at(names[i]);
  identify::VectorXd c;
  identify::MatrixXd dcdq;
  p.params->coefficients(q, c, dcdq);
  const identify::AssembledModel ops = identify::assemble(p.model(), c);
  const identify::NaturalModes nm = identify::natural_modes(ops.M, ops.K);
  double w = 0.0;
  int flexible = 0;
  for (int i = 0; i < nm.omega.size() && flexible < kResolvedModes; ++i)
    if (nm.omega[i] > nm.floor && std::isfinite(nm.omega[i])) {
      w = nm.omega[i];
      ++flexible;
    }
  const double h = p.scenario.simulation.sample_interval / 4.0;
  return w > 0 ? std::min(h, kPhaseStep / w) : h;
}

namespace {
// The FE problem of io::truth_scenario(scenario) on `elements` elements with every parameter at
// the truth file's value and the scenario's exact input signals.
struct AtTruth {
  io::Scenario sc;
  std::unique_ptr<identify::Problem> p;
  identify::VectorXd q;
};

AtTruth at_truth(const io::Scenario& scenario, const std::string& csv, int elements) {
  AtTruth a;
  a.sc = io::truth_scenario(scenario);
  io::Scenario& sc = a.sc;
  io::check_fe_reproduces_truth(scenario.source, sc,
                                 "the finite-element model cannot follow it, so the trajectories cannot be compared "
                                 "at the truth's physics");
  sc.truth.overrides.clear();
  sc.identification.elements = elements;
  sc.identification.time_step = 0.0;
  // Every quantity at the truth's value: the parameters by the truth file's true values (below),
  // the others from the structure, not from the identifier's starting guesses.
  sc.identification.initial.clear();
  for (auto& in : sc.inputs) in.signal_from = io::SignalFrom::Scenario;
  sc.identification.band_mode = io::IdentificationSpec::BandMode::None;  // trajectories compared whole
  a.p = identify::make_problem(sc, csv);
  const auto& names = a.p->params->names();
  a.q.resize(static_cast<Eigen::Index>(names.size()));
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto it = a.p->true_values.find(names[i]);
    if (it == a.p->true_values.end())
      throw io::InputError("truth file '" + csv + "': no true value for parameter '" + names[i] + "'");
    a.q[static_cast<Eigen::Index>(i)] = it->second;
  }
  return a;
}

FeResponse response_of(const AtTruth& a, identify::MatrixXd fe) {
  FeResponse r;
  r.t = a.p->data.t;
  r.fe = std::move(fe);
  r.measured = a.p->data.z;
  for (const auto& s : a.p->model().sensors) {
    r.sensors.push_back(s.name);
    r.kinds.push_back(io::to_string(s.kind));
  }
  return r;
}
}  // namespace

FeResponse fe_response(const io::Scenario& scenario, const std::string& csv, int elements, double step) {
  AtTruth a = at_truth(scenario, csv, elements);
  auto& so = a.p->objective_options.solver;
  so.integrator = identify::SolverOptions::Integrator::Esdirk;
  so.step = step > 0 ? step : fe_reference_step(*a.p);
  identify::Objective obj(a.p->model(), *a.p->params, a.p->signals, a.p->data, a.p->objective_options);
  return response_of(a, obj.predict(a.q));
}

FeResponse nonlinear_fe_response(const io::Scenario& scenario, const std::string& csv, int elements, double step) {
  const AtTruth a = at_truth(scenario, csv, elements);
  identify::VectorXd c;
  identify::MatrixXd dcdq;
  a.p->params->coefficients(a.q, c, dcdq);
  const identify::ScoleNonlinear nl = identify::scole_nonlinear(a.sc, elements);
  identify::NonlinearForwardOptions opt;
  opt.max_step = step > 0 ? step : fe_reference_step(*a.p);
  const auto r = identify::simulate_nonlinear(nl.at(c), a.p->signals, a.p->data.t, opt);
  return response_of(a, r.outputs);
}

TrajectoryReport compare_trajectories(const io::Scenario& scenario, const TrajectoryOptions& opt,
                                      const std::string& truth_root) {
  std::string why;
  if (!opt.IsValid(&why)) throw io::InputError("trajectories: " + why);
  if (opt.fe_step > 0 && !(scenario.simulation.duration / opt.fe_step <= io::limits::kMaxSteps))
    throw io::InputError("trajectories: --fe-step " + io::format_value(opt.fe_step) + " gives " +
                         io::format_value(std::ceil(scenario.simulation.duration / opt.fe_step)) + " steps over the " +
                         io::format_value(scenario.simulation.duration) + " s record; the limit is " +
                         io::format_value(io::limits::kMaxSteps));
  // The FE response is compared sample by sample: a step longer than the sample interval leaves
  // the record's own resolution unresolved (and one longer than the record is no integration).
  if (opt.fe_step > scenario.simulation.sample_interval)
    throw io::InputError("trajectories: --fe-step " + io::format_value(opt.fe_step) + " exceeds the record's sample interval " +
                         io::format_value(scenario.simulation.sample_interval) +
                         " s: the response would not be resolved between samples (leave it 0 for the automatic step)");
  if (opt.nonlinear && scenario.structure != io::Structure::Scole)
    throw io::InputError("trajectories: --nonlinear is SCOLE's nonlinear model; " + scenario.source + " has structure '" +
                         io::to_string(scenario.structure) + "'");
  const auto t0 = std::chrono::steady_clock::now();
  TrajectoryReport rep;
  rep.scenario = scenario.name;
  rep.truth_overrides = io::has_truth_overrides(scenario);
  rep.elements = opt.elements > 0 ? opt.elements : 4 * scenario.identification.elements;
  if (rep.elements > io::limits::kMaxElements) rep.elements = io::limits::kMaxElements;
  for (const auto& in : scenario.inputs) rep.input_kinds.push_back(std::string(io::to_string(in.at)) + " " + io::to_string(in.kind));
  rep.segments = refinement(opt.segments > 0 ? opt.segments : scenario.truth.segments, opt.levels,
                            io::limits::kMaxSegments, "segments");
  rep.truths = run_truth_levels(scenario, rep.segments, truth_root, true, opt.progress);
  const auto tf = std::chrono::steady_clock::now();
  // The FE response does not depend on the level: computed once, on the first level's times.
  const FeResponse fe = fe_response(scenario, rep.truths.front().csv, rep.elements, opt.fe_step);
  rep.fe_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - tf).count();
  FeResponse nl;
  if (opt.nonlinear) {
    rep.nonlinear_elements = opt.nonlinear_elements > 0 ? opt.nonlinear_elements : rep.elements;
    if (opt.progress)
      std::fprintf(stderr, "scole-crosscheck: nonlinear FE model, %d elements\n", rep.nonlinear_elements);
    const auto tn = std::chrono::steady_clock::now();
    nl = nonlinear_fe_response(scenario, rep.truths.front().csv, rep.nonlinear_elements, opt.fe_step);
    rep.nonlinear_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - tn).count();
  }
  const int ns = static_cast<int>(fe.sensors.size());
  for (int k = 0; k < ns; ++k) rep.sensors.push_back({fe.sensors[static_cast<std::size_t>(k)], fe.kinds[static_cast<std::size_t>(k)], {}, std::numeric_limits<double>::quiet_NaN(), {}});
  for (std::size_t l = 0; l < rep.truths.size(); ++l) {
    // The FE part does not depend on the level; each level contributes its measured columns.
    Eigen::MatrixXd measured = fe.measured;
    if (l > 0) {
      const io::DataTable tab = io::read_csv(rep.truths[l].csv);
      if (tab.t.size() != fe.t.size())
        throw std::runtime_error("truth levels sampled differently (" + std::to_string(tab.t.size()) + " vs " +
                                 std::to_string(fe.t.size()) + " samples)");
      for (int k = 0; k < ns; ++k) {
        const int c = tab.find(fe.sensors[static_cast<std::size_t>(k)]);
        if (c < 0) throw std::runtime_error("truth file '" + tab.source + "': no column " + fe.sensors[static_cast<std::size_t>(k)]);
        for (std::size_t i = 0; i < tab.t.size(); ++i)
          measured(static_cast<Eigen::Index>(i), k) = tab.columns[static_cast<std::size_t>(c)][i];
      }
    }
    for (int k = 0; k < ns; ++k) {
      const double num = (measured.col(k) - fe.fe.col(k)).norm(), den = measured.col(k).norm();
      rep.sensors[static_cast<std::size_t>(k)].relative_rms.push_back(den > 0 ? num / den : std::numeric_limits<double>::quiet_NaN());
      if (opt.nonlinear) {
        const double d = (measured.col(k) - nl.fe.col(k)).norm();
        rep.sensors[static_cast<std::size_t>(k)].nonlinear_relative_rms.push_back(
            den > 0 ? d / den : std::numeric_limits<double>::quiet_NaN());
      }
    }
    if (l + 1 == rep.truths.size()) {
      rep.t = fe.t;
      rep.chain = measured;
      rep.fe = fe.fe;
      if (opt.nonlinear) rep.nonlinear = nl.fe;
    }
  }
  for (auto& s : rep.sensors) {
    const auto L = s.relative_rms.size();
    if (L >= 2) s.rate = std::log2(s.relative_rms[L - 2] / s.relative_rms[L - 1]);
  }
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return rep;
}

Table trajectories_table(const TrajectoryReport& r) {
  Table t;
  t.title = "Trajectory agreement, " + r.scenario + ": relative RMS difference Simbody chain - FE (N=" +
            std::to_string(r.elements) + "), %";
  t.header = {"sensor", "kind"};
  for (int n : r.segments) t.header.push_back("n=" + std::to_string(n));
  t.header.push_back("rate");
  const bool nl = r.nonlinear_elements > 0;
  if (nl) {
    t.title += "; nonlinear FE (N=" + std::to_string(r.nonlinear_elements) + ") beside it";
    for (int n : r.segments) t.header.push_back("nonlinear n=" + std::to_string(n));
  }
  for (const auto& s : r.sensors) {
    std::vector<std::string> row{s.name, s.kind};
    for (double d : s.relative_rms) row.push_back(percent(d, 3));
    row.push_back(number(s.rate, 3));
    if (nl)
      for (double d : s.nonlinear_relative_rms) row.push_back(percent(d, 3));
    t.rows.push_back(row);
  }
  return t;
}

Table overlay_table(const TrajectoryReport& r) {
  Table t;
  t.header.push_back("t");
  for (const auto& s : r.sensors) {
    t.header.push_back(s.name + "_chain");
    t.header.push_back(s.name + "_fe");
    t.header.push_back(s.name + "_residual");
    if (r.nonlinear.size() != 0) t.header.push_back(s.name + "_nonlinear");
  }
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    std::vector<std::string> row{number(r.t[i], 10)};
    const auto ii = static_cast<Eigen::Index>(i);
    for (int k = 0; k < static_cast<int>(r.sensors.size()); ++k) {
      row.push_back(number(r.chain(ii, k), 10));
      row.push_back(number(r.fe(ii, k), 10));
      row.push_back(number(r.chain(ii, k) - r.fe(ii, k), 6));
      if (r.nonlinear.size() != 0) row.push_back(number(r.nonlinear(ii, k), 10));
    }
    t.rows.push_back(row);
  }
  return t;
}

nlohmann::json to_json(const TrajectoryReport& r) {
  const auto num = json_number;
  nlohmann::json j;
  j["scenario"] = r.scenario;
  j["truth_overrides"] = r.truth_overrides;
  j["elements"] = r.elements;
  j["segments"] = r.segments;
  j["inputs"] = r.input_kinds;
  j["sensors"] = nlohmann::json::array();
  for (const auto& s : r.sensors) {
    nlohmann::json e;
    e["name"] = s.name;
    e["kind"] = s.kind;
    nlohmann::json d = nlohmann::json::array();
    for (double v : s.relative_rms) d.push_back(num(v));
    e["relative_rms"] = d;
    e["rate"] = num(s.rate);
    if (r.nonlinear_elements > 0) {
      nlohmann::json dn = nlohmann::json::array();
      for (double v : s.nonlinear_relative_rms) dn.push_back(num(v));
      e["nonlinear_relative_rms"] = dn;
    }
    j["sensors"].push_back(e);
  }
  nlohmann::json tr = nlohmann::json::array();
  for (const auto& l : r.truths)
    tr.push_back({{"segments", l.segments}, {"file", "truths/n" + std::to_string(l.segments) + "/truth.csv"}, {"seconds", l.seconds}, {"integrator", l.summary.integrator}});
  j["truths"] = tr;
  j["fe_seconds"] = r.fe_seconds;
  if (r.nonlinear_elements > 0) {
    j["nonlinear_elements"] = r.nonlinear_elements;
    j["nonlinear_seconds"] = r.nonlinear_seconds;
  }
  j["seconds"] = r.seconds;
  return j;
}

}  // namespace scoleid::crosscheck
