// identify.json, fit.csv / fit.gp / fit.png and the printed summary of one identification run
// (identify_run.h; the file format: docs/theory.md §10).
#include <cmath>
#include <csignal>
#include <cstdio>
#include <tuple>

#include "scoleid/identify/inverse/spectral_start.h"
#include "scoleid/identify/run/fit_plot.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"
#include "scoleid/io/run_directory.h"

namespace scoleid::identify {

using nlohmann::json;

namespace {

double safe(double v) { return std::isfinite(v) ? v : 0.0; }
json finite_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

std::string integrator_name(const SolverOptions& o) {
  switch (o.integrator) {
    case SolverOptions::Integrator::Esdirk: return ButcherTable::name(o.dirk_table);
    case SolverOptions::Integrator::EsdirkArkode: return "arkode-" + ButcherTable::name(o.dirk_table);
    case SolverOptions::Integrator::Bdf: return "cvodes-bdf";
  }
  return "?";
}

// The interval (interval.h) of parameter i: ±half_width about the estimate, and what it is made of.
json interval_json(const RunResult& r, Eigen::Index i, const double* truth) {
  const double hw = r.interval.half_width.size() > i ? r.interval.half_width[i] : std::nan("");
  if (!std::isfinite(hw)) return nullptr;
  const auto& in = r.interval;
  json comp{{"noise_2std", in.noise[i]},
            {"residual_2resolution", in.residual[i]},
            {"half_record_shift", in.half_record_shift[i]},
            {"smoothing_shift", in.smoothing_shift[i]},
            {"consider", in.consider[i]}};
  const double q = r.estimate[i];
  json e{{"half_width", hw}, {"low", q - hw}, {"high", q + hw}, {"relative_half_width", hw / std::abs(q)}, {"components", comp}};
  if (truth) e["covers_truth"] = std::abs(q - *truth) <= hw;
  return e;
}

json parameter_json(const RunResult& r, std::size_t i) {
  const auto ie = static_cast<Eigen::Index>(i);
  json e{{"name", r.names[i]}, {"initial", r.initial[ie]}, {"estimate", r.estimate[ie]}};
  const auto it = r.truth.find(r.names[i]);
  const double* truth = it != r.truth.end() ? &it->second : nullptr;
  if (truth) {
    e["truth"] = *truth;
    e["relative_error"] = r.estimate[ie] / *truth - 1.0;
  }
  if (r.ident.std.size() <= ie) {
    // --no-std: not assessed, which is not the same as identifiable.
    e["std"] = e["resolution"] = e["identifiable"] = e["interval"] = nullptr;
    return e;
  }
  // A flagged parameter has no standard deviation worth the name: null, with the reason.
  const bool ok = r.ident.identifiable[i];
  e["std"] = ok ? finite_or_null(r.ident.std[ie]) : json(nullptr);
  e["resolution"] = ok ? finite_or_null(r.ident.resolution[ie]) : json(nullptr);
  e["identifiable"] = ok;
  if (!ok && i < r.ident.reason.size()) e["not_identifiable_because"] = r.ident.reason[i];
  e["interval"] = ok ? interval_json(r, ie, truth) : json(nullptr);
  if (r.half_record_estimate.size() > ie) e["half_record_estimate"] = r.half_record_estimate[ie];
  return e;
}

json fit_test_json(const FitTest& fit) {
  json sens = json::array();
  for (const auto& sf : fit.sensors)
    sens.push_back({{"name", sf.name}, {"rms_signal", sf.rms_signal}, {"rms_residual", sf.rms_residual},
                    {"noise", sf.noise}, {"noise_estimated", sf.noise_estimated}, {"noise_origin", sf.noise_origin}, {"systematic", sf.systematic},
                    {"discretisation", finite_or_null(sf.discretisation)},
                    {"allowed", sf.allowed}, {"explained", sf.explained}});
  return {{"explains_data", fit.explains_data},
          {"within_noise_and_discretisation", fit.within_noise_and_discretisation},
          {"model_error", fit.model_error}, {"model_error_needed", finite_or_null(fit.model_error_needed)}, {"ratio", fit.ratio},
          {"message", fit.message}, {"sensors", sens}};
}

json attempts_json(const RunResult& r) {
  json a = json::array();
  for (std::size_t k = 0; k < r.attempts.size(); ++k) {
    const auto& at = r.attempts[k];
    a.push_back({{"strategy", at.strategy}, {"method", io::to_string(at.method)},
                 {"termination", at.termination}, {"optimizer_converged", at.optimizer_converged},
                 {"cost", finite_or_null(at.cost)},
                 {"iterations", at.iterations}, {"explains_data", at.explains_data},
                 {"fit_message", at.fit_message}, {"chosen", static_cast<int>(k) == r.chosen_attempt}});
    for (const auto& l : at.levels)
      a.back()["levels"].push_back({{"blocks", l.blocks}, {"step", l.step}, {"cost", finite_or_null(l.cost)},
                                    {"iterations", l.iterations}, {"termination", l.termination},
                                    {"explained", l.explained}});
  }
  return a;
}

json smoothness_json(const RunResult& r) {
  json sm{{"weight", r.smoothness_weight}, {"prior_cost", r.summary.prior_cost}};
  if (r.smoothness_path.empty()) return sm;
  sm["rule"] = "discrepancy";
  sm["expected_misfit"] = r.smoothness_expected_misfit;  // noise and the fit test's floor
  sm["discrepancy_met"] = r.smoothness_met;
  json path = json::array();
  for (const auto& e : r.smoothness_path)
    path.push_back({{"weight", e.weight}, {"data_misfit", e.data_misfit}, {"prior_cost", e.prior_cost},
                    {"iterations", e.iterations}, {"converged", e.converged}});
  sm["path"] = path;
  return sm;
}

json integrator_json(const RunResult& r, const Problem& p) {
  const bool nonlinear = r.model == io::Model::Nonlinear;
  const auto& id = p.scenario.identification;
  return {{"name", nonlinear ? std::string("esdirk-newton (nonlinear model)")
                             : integrator_name(p.objective_options.solver)},
          {"step", nonlinear ? r.integrator_step : p.objective_options.solver.step},
          {"rtol", nonlinear ? json(nullptr) : json(p.objective_options.solver.rtol)},
          {"steps", r.counters.solver.steps},
          {"step_rule", id.time_step > 0 ? std::string("given") : std::string(io::to_string(id.step_rule))},
          {"resolved_modes", p.content.mode},
          {"modes_below_nyquist", p.content.modes_below_nyquist},
          {"visible_content_modes", p.content.content_mode}};
}

json correlation_json(const RunResult& r) {
  const MatrixXd R = correlation(r.ident);
  json rows = json::array();
  for (Eigen::Index i = 0; i < R.rows(); ++i) {
    json row = json::array();
    for (Eigen::Index j = 0; j < R.cols(); ++j) row.push_back(finite_or_null(R(i, j)));
    rows.push_back(row);
  }
  return {{"parameters", r.names}, {"matrix", rows}};
}

json identifiability_json(const RunResult& r) {
  if (r.ident.std.size() == 0)
    return {{"assessed", false}, {"why", "run with --no-std: no standard deviations, no identifiability flags"}};
  json consider = json::array();
  for (const auto& t : r.interval.terms) {
    json sh = json::object();
    for (std::size_t i = 0; i < r.names.size() && static_cast<Eigen::Index>(i) < t.shift.size(); ++i)
      sh[r.names[i]] = t.shift[static_cast<Eigen::Index>(i)];
    consider.push_back({{"field", t.field}, {"value", t.value}, {"tolerance", t.delta}, {"shift", sh}});
  }
  return {{"assessed", true},
          {"condition_number", safe(r.ident.condition_number)},
          {"noise_std", r.ident.noise_std},
          {"noise_source", r.ident.noise_source},
          {"chi2", r.ident.chi2},
          {"data_values", r.ident.data_values},
          {"mirror_chi2_difference", finite_or_null(r.ident.mirror_chi2_difference)},
          {"other_minimum_chi2_difference", finite_or_null(r.ident.other_minimum_chi2_difference)},
          {"correlation", correlation_json(r)},
          {"half_record_refit_converged", r.half_record_estimate.size() != 0 ? json(r.half_record_converged) : json(nullptr)},
          {"consider", consider},
          {"interval_note", r.interval.note}};
}

// The identified model's elastic modes (modal_uncertainty.h), lowest first.
json modes_json(const RunResult& r) {
  json modes = json::array();
  for (const auto& m : r.modes) {
    json e{{"mode", m.mode},
           {"frequency_hz", m.frequency_hz},
           {"frequency_std_hz", finite_or_null(m.frequency_std_hz)},
           {"frequency_interval_hz", finite_or_null(m.frequency_half_width_hz)},
           {"damping_ratio", finite_or_null(m.damping_ratio)},
           {"damping_ratio_std", finite_or_null(m.damping_std)},
           {"damping_ratio_interval", finite_or_null(m.damping_half_width)}};
    if (!m.note.empty()) e["uncertainty_not_given_because"] = m.note;
    // The record's own mode (inverse/record_modes.h), and the model-form terms it added.
    if (std::isfinite(m.record_frequency_hz))
      e["record"] = {{"frequency_hz", m.record_frequency_hz},
                     {"frequency_std_hz", m.record_frequency_std_hz},
                     {"damping_ratio", m.record_damping_ratio},
                     {"damping_ratio_std", m.record_damping_std},
                     {"frequency_model_form_hz", m.frequency_model_form_hz},
                     {"damping_ratio_model_form", m.damping_model_form}};
    modes.push_back(e);
  }
  return modes;
}

json data_columns_json(const ColumnUse& c) {
  json stepped = json::array();
  for (const auto& st : c.stepped_inputs) {
    stepped.push_back({{"name", st.name}, {"largest_jump", st.jump}, {"at", st.at}, {"switch_shift_up_to", 0.5 * st.sample},
                       {"scenario_gives_signal", st.scenario_signal}, {"pulse_samples", st.pulse_samples},
                       {"interpolation", st.cubic ? "cubic" : "linear"}});
    if (st.windowed) {
      json hits = json::array();
      for (const auto& [at, rel] : st.hits) hits.push_back({{"at", at}, {"relative_peak", rel}});
      stepped.back()["force_window"] = {{"from", st.window_from}, {"to", st.window_to}, {"hits", hits}};
    }
  }
  json interpolation = json::array();
  for (const auto k : c.input_interpolation) interpolation.push_back(io::to_string(k));
  json sources = json::array();
  for (const auto& x : c.sources) {
    sources.push_back({{"name", x.name}, {"column", x.column}, {"column_unit", x.from_unit}, {"unit_stated_by", x.unit_stated_by},
                       {"unit", x.to_unit}, {"scale", x.scale}});
    if (x.conditioned)
      sources.back()["conditioning"] = {{"offset_removed", x.offset_removed},
                                        {"factor", x.factor},
                                        {"trend_removed", {{"mean", x.trend_removed.first}, {"slope", x.trend_removed.second}}}};
  }
  return {{"sensors", c.sensors},
          {"sources", sources},
          {"inputs_from_data", c.inputs_from_data},
          {"input_interpolation", interpolation},
          {"inputs_from_scenario", c.inputs_from_scenario},
          {"unused", c.unused},
          {"stepped_inputs", stepped},
          {"time",
           {{"uniform", c.time.uniform},
            {"step", c.time.uniform ? json(c.time.step) : json(nullptr)},
            {"sample_rate_hz", c.time.uniform ? json(1.0 / c.time.step) : json(nullptr)},
            {"written_precision", c.time.precision},
            {"largest_shift_to_grid", c.time.max_shift},
            {"placed_on_grid", c.time_regularised}}},
          {"quiet_start",
           c.quiet_samples > 0 ? json{{"trigger_time", c.trigger_time}, {"samples", c.quiet_samples}} : json(nullptr)},
          {"fit_window", c.window.size() == 2 ? json(c.window) : json(nullptr)}};
}

json counts_json(const RunResult& r, json& out) {
  const auto& c = r.counters;
  out["krylov_iterations"] = r.summary.krylov_iterations;
  // Every attempt's iterations with its coarse-to-fine levels (`iterations` is the chosen run's
  // history alone).
  out["iterations_all_attempts"] = r.iterations_all_attempts();
  out["gradient_evaluations"] = c.gradient_evaluations;
  out["forward_solves"] = c.forward_solves;
  out["costate_solves"] = c.costate_solves;
  out["sensitivity_solves"] = c.sensitivity_solves;
  out["checkpointed_passes"] = c.checkpointed_passes;
  out["checkpoint_resolves"] = c.checkpoint_resolves;
  out["wall_seconds"] = r.wall_seconds;
  out["timing_seconds"] = {{"forward", c.forward_seconds},
                           {"costate", c.costate_seconds},
                           {"sensitivity", c.sensitivity_seconds},
                           {"quadrature", c.quadrature_seconds},
                           {"optimizer_total", r.summary.wall_seconds},
                           {"identifiability", r.identifiability_seconds},
                           {"record_modes", r.record_modes.seconds}};
  return out;
}

// The correlation of the estimates, for two to eight parameters with a covariance.
std::string correlation_table(const RunResult& r) {
  const MatrixXd R = correlation(r.ident);
  const auto P = R.rows();
  if (P < 2 || P > 8) return "";
  std::string s = "\ncorrelation of the estimates\n";
  char cell[64];
  std::snprintf(cell, sizeof cell, "%-10s", "");
  s += cell;
  for (Eigen::Index j = 0; j < P; ++j) {
    std::snprintf(cell, sizeof cell, " %9.9s", r.names[static_cast<std::size_t>(j)].c_str());
    s += cell;
  }
  s += "\n";
  for (Eigen::Index i = 0; i < P; ++i) {
    std::snprintf(cell, sizeof cell, "%-10s", r.names[static_cast<std::size_t>(i)].c_str());
    s += cell;
    for (Eigen::Index j = 0; j < P; ++j) {
      if (std::isfinite(R(i, j))) std::snprintf(cell, sizeof cell, " %9.4f", R(i, j));
      else std::snprintf(cell, sizeof cell, " %9s", "-");
      s += cell;
    }
    s += "\n";
  }
  return s;
}

// The identified model's modes with std and interval half-width.
std::string modes_table(const std::vector<ModalEstimate>& modes) {
  if (modes.empty()) return "";
  std::string s = "\nmodes of the identified model\n";
  char line[256];
  std::snprintf(line, sizeof line, "%5s %14s %12s %12s %14s %12s %12s\n", "mode", "frequency_Hz", "std", "± interval",
                "damping_ratio", "std", "± interval");
  s += line;
  auto cell = [](double v, const char* fmt) {
    char buf[32] = "-";
    if (std::isfinite(v)) std::snprintf(buf, sizeof buf, fmt, v);
    return std::string(buf);
  };
  for (const auto& m : modes) {
    std::snprintf(line, sizeof line, "%5d %14s %12s %12s %14s %12s %12s%s%s\n", m.mode, cell(m.frequency_hz, "%.7g").c_str(),
                  cell(m.frequency_std_hz, "%.3e").c_str(), cell(m.frequency_half_width_hz, "%.3e").c_str(),
                  cell(m.damping_ratio, "%.5g").c_str(), cell(m.damping_std, "%.3e").c_str(),
                  cell(m.damping_half_width, "%.3e").c_str(), m.note.empty() ? "" : "  ", m.note.c_str());
    s += line;
  }
  // Where the record places a mode away from the model's (record_modes.h): the model's form, in
  // the interval above.
  for (const auto& m : modes) {
    if (m.frequency_model_form_hz > 0) {
      std::snprintf(line, sizeof line,
                    "mode %d: the record has it at %.7g Hz (std %.2e), %.3g std from the model's: the model's form cannot place "
                    "it there; its interval holds the miss\n",
                    m.mode, m.record_frequency_hz, m.record_frequency_std_hz,
                    std::abs(m.record_frequency_hz - m.frequency_hz) / m.record_frequency_std_hz);
      s += line;
    }
    if (m.damping_model_form > 0) {
      std::snprintf(line, sizeof line,
                    "mode %d: the record's damping ratio is %.5g (std %.2e), %.3g std from the model's: the model's form cannot "
                    "give it; its interval holds the miss\n",
                    m.mode, m.record_damping_ratio, m.record_damping_std,
                    std::abs(m.record_damping_ratio - m.damping_ratio) / m.record_damping_std);
      s += line;
    }
  }
  return s;
}

}  // namespace

namespace {
// identify.json "frf": how a frequency-domain run's FRFs were made and started (null in the time domain).
nlohmann::json frf_json(const Problem& p, const RunResult& r) {
  if (!p.frf) return nullptr;
  const io::FrfData& d = *p.frf;
  nlohmann::json sensors = nlohmann::json::array();
  for (std::size_t s = 0; s < d.channels.size(); ++s) {
    double chi2 = 0.0;
    for (std::size_t k = 0; k < d.f_hz.size() && r.frf_model.rows() == d.lines(); ++k)
      chi2 += 2.0 * std::norm(r.frf_model(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(s)) - d.channels[s].H[k]) / d.channels[s].variance[k];
    sensors.push_back({{"name", d.channels[s].sensor}, {"chi2", r.frf_model.rows() == d.lines() ? nlohmann::json(chi2) : nlohmann::json(nullptr)},
                       {"values", 2 * d.lines()}});
  }
  return {{"estimator", d.estimator}, {"input", p.scenario.inputs[static_cast<std::size_t>(p.frf_input)].name}, {"lines", d.lines()},
          {"f_min_hz", d.f_hz.front()}, {"f_max_hz", d.f_hz.back()}, {"averages", d.averages}, {"decay", d.decay},
          {"variance_degrees_of_freedom", p.frf_variance_dof > 0 ? nlohmann::json(p.frf_variance_dof) : nlohmann::json("known")},
          {"note", p.frf_note}, {"start", r.frf_start_note}, {"passes", r.frf_passes}, {"factorisations", r.frf_factorisations},
          {"sensors", sensors}};
}

json band_json(const Problem& p) {
  const auto& band = p.scenario.identification.band;
  if (band.empty()) return p.band_note.empty() ? json(nullptr) : json{{"chosen", "auto"}, {"note", p.band_note}};
  return {{"f_lo_hz", band[0]},
          {"f_hi_hz", band[1]},
          {"noise_gain", p.band_gain},
          {"chosen", p.band_note.empty() ? "stated" : "auto"},
          {"note", p.band_note.empty() ? "the scenario's identification.band" : p.band_note}};
}

json initial_state_json(const Problem& p, const RunResult& r) {
  if (p.scenario.identification.initial_state != io::InitialState::Estimate)
    return {{"estimated", false}, {"note", "the structure at rest at the first sample"}};
  const auto m = static_cast<Eigen::Index>(r.initial_state_hz.size());
  std::vector<double> a, b;
  if (r.initial_state_coefficients.size() == 2 * m)
    for (Eigen::Index j = 0; j < m; ++j) {
      a.push_back(r.initial_state_coefficients[j]);
      b.push_back(r.initial_state_coefficients[m + j]);
    }
  return {{"estimated", true},
          {"modes", m},
          {"basis_hz", r.initial_state_hz},
          {"displacement", a},
          {"velocity", b},
          {"note", "x(t0) = sum of displacement[j] phi_j, x'(t0) = sum of velocity[j] phi_j, phi_j the basis "
                   "model's M-orthonormal modes at basis_hz; profiled out of the fit, its unknowns counted in "
                   "every interval"}};
}

json start_check_json(const StartCheck& c) {
  json sensors = json::array();
  for (const auto& s : c.sensors)
    sensors.push_back({{"name", s.name},
                       {"correlation", std::isfinite(s.correlation) ? json(s.correlation) : json(nullptr)},
                       {"scale", std::isfinite(s.scale) ? json(s.scale) : json(nullptr)}});
  json out = {{"from", c.from}, {"to", c.to}, {"sensors", sensors}, {"warnings", c.warnings}};
  json frf = json::array();
  auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  for (const auto& r : c.frf) {
    json lines = json::array();
    for (const auto& l : r.lines)
      lines.push_back({{"hz", l.hz}, {"measured", number(l.measured)}, {"model", number(l.model)}, {"ratio", number(l.ratio)},
                       {"phase_deg", number(l.phase_deg)}});
    frf.push_back({{"input", r.input}, {"sensor", r.sensor}, {"median_ratio", number(r.median_ratio)},
                   {"median_abs_phase_deg", number(r.median_phase_deg)}, {"lines", lines}});
  }
  out["frf"] = frf;
  if (!c.frf_note.empty()) out["frf_note"] = c.frf_note;
  return out;
}

json residual_bands_json(const Problem& p, const ResidualBands& rb) {
  json bands = json::array();
  for (const auto& b : rb.bands) {
    json rms = json::object();
    for (std::size_t j = 0; j < b.rms.size() && j < p.data.names.size(); ++j) rms[p.data.names[j]] = b.rms[j];
    bands.push_back({{"from_hz", b.from_hz}, {"to_hz", b.to_hz}, {"holds", b.holds}, {"mode", b.mode}, {"share", b.share}, {"rms", rms}});
  }
  return {{"bands", bands}, {"at_modes", rb.at_modes}, {"summary", rb.summary}, {"note", rb.note}};
}
}  // namespace

nlohmann::json RunResult::to_json(const Problem& p) const {
  json params = json::array();
  for (std::size_t i = 0; i < names.size(); ++i) params.push_back(parameter_json(*this, i));
  json iters = json::array();
  for (const auto& it : summary.iterations) {
    json values = json::object();
    for (std::size_t i = 0; i < names.size(); ++i) values[names[i]] = it.q[static_cast<Eigen::Index>(i)];
    iters.push_back({{"k", it.k}, {"cost", it.cost}, {"values", values}, {"physical", p.params->physical(it.q)},
                     {"gradient_norm", it.gradient_norm}, {"horizon", it.horizon}});
  }
  json out{{"scenario", scenario},
           {"model", io::to_string(model)},
           {"method", io::to_string(method)},
           {"parameters", params},
           {"physical_estimate", p.params->physical(estimate)},
           {"iterations", iters},
           {"termination", to_string(summary.termination)},
           {"termination_message", summary.message},
           {"converged", converged()},
           {"optimizer_converged", summary.converged()},
           {"fit_test", fit_test_json(fit)},
           {"domain", io::to_string(p.scenario.identification.domain)},
           {"frf", frf_json(p, *this)},
           {"attempts", attempts_json(*this)},
           {"cost", summary.cost},
           {"smoothness", smoothness_json(*this)},
           {"integrator", p.frf ? json(nullptr) : integrator_json(*this, p)},  // a frequency-domain run integrates nothing
           {"data_source", p.data_source},
           {"elements", p.structure->elements()},
           {"settings", io::to_json(p.scenario)},
           {"identifiability", identifiability_json(*this)},
           {"modes", modes_json(*this)},
           {"band", band_json(p)}};
  out["initial_state"] = initial_state_json(p, *this);
  counts_json(*this, out);
  if (p.origin != Problem::DataOrigin::Synthesis) out["data_columns"] = data_columns_json(p.columns);
  if (!start_check.sensors.empty()) out["start_check"] = start_check_json(start_check);
  if (!p.warnings.empty()) out["data_warnings"] = p.warnings;
  if (interrupted_by != 0)
    out["interrupted"] = {{"signal", interrupted_by == SIGALRM ? "wall-time limit" : interrupted_by == SIGINT ? "SIGINT" : interrupted_by == SIGTERM ? "SIGTERM" : std::to_string(interrupted_by)},
                          {"note", interrupted_note}};
  if (!residual_bands.bands.empty() || !residual_bands.note.empty()) out["residual_bands"] = residual_bands_json(p, residual_bands);
  return out;
}

std::string RunResult::FullReport() const {
  std::string s;
  char line[512];
  std::snprintf(line, sizeof line, "%-10s %14s %14s %14s %12s %12s %12s %12s\n", "parameter", "initial", "estimate", "truth",
                "rel.error", "std", "resolution", "± interval");
  s += line;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto it = truth.find(names[i]);
    const auto e = static_cast<Eigen::Index>(i);
    const double est = estimate[e];
    auto cell = [&](const VectorXd& v) {
      char buf[32] = "-";
      if (v.size() > e && std::isfinite(v[e])) std::snprintf(buf, sizeof buf, "%12.3e", v[e]);
      return std::string(buf);
    };
    const bool flagged = ident.identifiable.size() && !ident.identifiable[i];
    const char* flag = flagged ? "  NOT IDENTIFIABLE" : ident.identifiable.empty() ? "  (not assessed)" : "";
    const std::string sd = flagged ? "-" : cell(ident.std), res = flagged ? "-" : cell(ident.resolution),
                      hw = flagged ? "-" : cell(interval.half_width);
    if (it != truth.end())
      std::snprintf(line, sizeof line, "%-10s %14.7g %14.7g %14.7g %12.3e %12s %12s %12s%s\n", names[i].c_str(), initial[e], est,
                    it->second, est / it->second - 1.0, sd.c_str(), res.c_str(), hw.c_str(), flag);
    else
      std::snprintf(line, sizeof line, "%-10s %14.7g %14.7g %14s %12s %12s %12s %12s%s\n", names[i].c_str(), initial[e], est, "-",
                    "-", sd.c_str(), res.c_str(), hw.c_str(), flag);
    s += line;
  }
  // Why a flagged parameter is not identifiable, one line each (the table's flag alone says not what).
  for (std::size_t i = 0; i < names.size() && i < ident.identifiable.size() && i < ident.reason.size(); ++i)
    if (!ident.identifiable[i] && !ident.reason[i].empty()) s += "  " + names[i] + ": " + ident.reason[i] + "\n";
  s += correlation_table(*this);
  s += modes_table(modes);
  if (!residual_bands.summary.empty()) s += "\n" + residual_bands.summary + "\n";
  if (!initial_state_hz.empty()) {
    char which[96];
    if (initial_state_hz.size() == 1) std::snprintf(which, sizeof which, "lowest mode (%.4g Hz)", initial_state_hz.front());
    else
      std::snprintf(which, sizeof which, "%zu lowest modes (%.4g to %.4g Hz)", initial_state_hz.size(), initial_state_hz.front(),
                    initial_state_hz.back());
    std::snprintf(line, sizeof line,
                  "\ninitial state: estimated in the start model's %s, %zu unknowns profiled out of the fit and counted in "
                  "every interval\n",
                  which, 2 * initial_state_hz.size());
    s += line;
  }
  if (frf_passes > 0)  // a frequency-domain run integrates nothing: its work is the lines' complex factorisations
    std::snprintf(line, sizeof line, "\n%s; %ld passes over the lines, %ld complex factorisations; %.3f s\n",
                  summary.BriefReport().c_str(), frf_passes, frf_factorisations, wall_seconds);
  else
    std::snprintf(line, sizeof line, "\n%s; %ld forward, %ld costate, %ld sensitivity solves; %.3f s\n",
                  summary.BriefReport().c_str(), counters.forward_solves, counters.costate_solves, counters.sensitivity_solves,
                  wall_seconds);
  return s + line;
}

io::DataTable fit_table(const Measurements& data, const MatrixXd& Y) {
  io::DataTable tab;
  tab.t = data.t;
  for (int k = 0; k < data.sensors(); ++k) {
    const std::string& n = data.names[static_cast<std::size_t>(k)];
    std::vector<double> m(data.t.size()), y(data.t.size()), e(data.t.size());
    for (std::size_t i = 0; i < data.t.size(); ++i) {
      m[i] = data.z(static_cast<Eigen::Index>(i), k);
      y[i] = Y(static_cast<Eigen::Index>(i), k);
      e[i] = y[i] - m[i];
    }
    tab.names.insert(tab.names.end(), {n + "_measured", n + "_predicted", n + "_residual"});
    tab.columns.insert(tab.columns.end(), {m, y, e});
  }
  return tab;
}

namespace {

// The plot's title: the run, its verdict and its first estimates with their intervals.
std::string plot_title(const RunResult& r) {
  std::string t = r.scenario + ": ";
  if (r.converged()) t += "converged";
  else
    t += "NOT converged (" +
         std::string(!r.summary.converged()   ? to_string(r.summary.termination)
                     : r.determines_nothing() ? "the data determine no parameter"
                                              : "the fit test rejects the fit") +
         ")";
  for (std::size_t i = 0; i < r.names.size() && i < 4; ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    char buf[96];
    const double hw = r.interval.half_width.size() > e ? r.interval.half_width[e] : std::nan("");
    const bool flagged = !r.ident.identifiable.empty() && !r.ident.identifiable[i];
    if (flagged) std::snprintf(buf, sizeof buf, "; %s %.5g (not identifiable)", r.names[i].c_str(), r.estimate[e]);
    else if (std::isfinite(hw)) std::snprintf(buf, sizeof buf, "; %s %.5g ± %.2g", r.names[i].c_str(), r.estimate[e], hw);
    else std::snprintf(buf, sizeof buf, "; %s %.5g", r.names[i].c_str(), r.estimate[e]);
    t += buf;
  }
  if (r.names.size() > 4) t += "; " + std::to_string(r.names.size()) + " parameters in all";
  return t;
}

// About ten cycles of the record's dominant frequency from where the response starts (the first
// sample where a sensor exceeds a tenth of its largest value), when that is under half the record.
std::pair<double, double> zoom_window(const Measurements& data) {
  const auto f = dominant_frequency(data.t, data.z);
  if (!f || data.t.size() < 2) return {0.0, 0.0};
  const double span = data.t.back() - data.t.front(), width = 10.0 / *f;
  if (!(width < 0.5 * span)) return {0.0, 0.0};
  std::size_t first = data.t.size() - 1;
  for (Eigen::Index k = 0; k < data.z.cols(); ++k) {
    const double peak = data.z.col(k).cwiseAbs().maxCoeff();
    for (std::size_t i = 0; i < data.t.size(); ++i)
      if (std::abs(data.z(static_cast<Eigen::Index>(i), k)) > 0.1 * peak) {
        first = std::min(first, i);
        break;
      }
  }
  const double from = std::max(data.t.front(), data.t[first] - 0.1 * width);
  return {from, std::min(data.t.back(), from + width)};
}

std::vector<std::string> sensor_units(const Problem& p) {
  std::vector<std::string> u;
  for (const auto& s : p.scenario.sensors) u.push_back(s.unit);
  return u;
}

void render(const char* png, RenderStatus status) {
  switch (status) {
    case RenderStatus::Rendered: break;
    case RenderStatus::NoGnuplot: std::fprintf(stderr, "scole-identify: note: gnuplot is not installed; no %s\n", png); break;
    case RenderStatus::Failed: std::fprintf(stderr, "scole-identify: note: gnuplot could not render %s\n", png); break;
  }
}

}  // namespace

MatrixXd predicted_outputs(Problem& p, const RunResult& r) {
  if (r.predicted.size() != 0) return r.predicted;
  Objective obj(p.model(), *p.params, p.signals, p.data, p.objective_options);
  return obj.predict(r.estimate);
}


// spectrum.csv / spectrum.gp: measured and predicted power spectral densities (false: none).
static bool write_spectrum(io::RunDirectory& dir, const Problem& p, const RunResult& r, const MatrixXd& predicted, const std::string& title) {
  const Spectrum sm = power_spectrum(p.data.t, p.data.z), sp = power_spectrum(p.data.t, predicted);
  if (sm.f.empty() || sm.psd.rows() != sp.psd.rows()) return false;
  io::DataTable spec;
  spec.t = sm.f;
  spec.time_name = "frequency_hz";
  for (int k = 0; k < p.data.sensors(); ++k) {
    const std::string& n = p.data.names[static_cast<std::size_t>(k)];
    spec.names.insert(spec.names.end(), {n + "_measured_psd", n + "_predicted_psd"});
    const VectorXd a = sm.psd.col(k), b = sp.psd.col(k);
    spec.columns.push_back(std::vector<double>(a.data(), a.data() + a.size()));
    spec.columns.push_back(std::vector<double>(b.data(), b.data() + b.size()));
  }
  io::write_csv(dir.path("spectrum.csv"), spec);
  std::vector<double> modes_hz;
  for (const auto& m : r.modes) modes_hz.push_back(m.frequency_hz);
  io::write_text_atomic(dir.path("spectrum.gp"), spectrum_plot_script(p.data.names, sensor_units(p), modes_hz, title,
                                                                      spectrum_view(sm.f, sm.psd, sp.psd, p.scenario.identification.band)));
  return true;
}

// start_frf.csv / start_frf.gp: the record's and the model's frequency responses at the start,
// per sensor (start_check.h; false: none).
static bool write_start_frf(io::RunDirectory& dir, const Problem& p, const RunResult& r) {
  if (r.start_check.frf.empty()) return false;
  const auto& first = r.start_check.frf.front();
  io::DataTable frf;
  frf.t = first.f;
  frf.time_name = "frequency_hz";
  std::string gp = "set terminal pngcairo size 1200," + std::to_string(300 * r.start_check.frf.size() + 40) +
                   " noenhanced\nset output 'start_frf.png'\nset datafile separator ','\nset multiplot layout " +
                   std::to_string(r.start_check.frf.size()) + ",2 title " +
                   gnuplot_quote(p.scenario.name + ": the record against the model at the start (H1 = response / input '" + first.input + "')") +
                   "\nset grid\nset key top right\nset xlabel 'frequency [Hz]'\nset logscale x\n" +
                   (first.f.size() > 1 ? "set xrange [" + io::format_value(first.f.front()) + ":" + io::format_value(first.f.back()) + "]\n"
                                       : std::string());
  int col = 2;
  for (const auto& pair : r.start_check.frf) {
    if (pair.f.size() != frf.t.size()) continue;
    std::vector<double> mm, pm, mp, pp;
    for (std::size_t b = 0; b < pair.f.size(); ++b) {
      mm.push_back(std::abs(pair.measured[b]));
      pm.push_back(std::abs(pair.model[b]));
      mp.push_back(std::arg(pair.measured[b]) * 180.0 / M_PI);
      pp.push_back(std::arg(pair.model[b]) * 180.0 / M_PI);
    }
    const std::string& n = pair.sensor;
    frf.names.insert(frf.names.end(), {n + "_measured_magnitude", n + "_model_magnitude", n + "_measured_phase_deg", n + "_model_phase_deg"});
    frf.columns.insert(frf.columns.end(), {mm, pm, mp, pp});
    const std::string c = std::to_string(col);
    gp += "set logscale y\nset format y '%g'\nset yrange [*:*]\nset title " + gnuplot_quote(n + ": magnitude") +
          "\nplot 'start_frf.csv' every ::1 using 1:" + c + " with lines lw 2 title 'measured', '' every ::1 using 1:" +
          std::to_string(col + 1) + " with lines dt 2 lw 2 title 'model at the start'\n";
    gp += "unset logscale y\nset yrange [-180:180]\nset ytics 90\nset title " + gnuplot_quote(n + ": phase [deg]") +
          "\nplot 'start_frf.csv' every ::1 using 1:" + std::to_string(col + 2) + " with points pt 7 ps 0.3 title 'measured', '' every ::1 using 1:" +
          std::to_string(col + 3) + " with points pt 6 ps 0.3 title 'model at the start'\nset ytics autofreq\n";
    col += 4;
  }
  gp += "unset multiplot\n";
  io::write_csv(dir.path("start_frf.csv"), frf);
  io::write_text_atomic(dir.path("start_frf.gp"), gp);
  return true;
}

void write_outputs(io::RunDirectory& dir, Problem& p, const RunResult& r) {
  if (p.frf) {
    io::write_csv(dir.path("fit.csv"), frf_fit_table(*p.frf, r.frf_model));
    io::write_text_atomic(dir.path("fit.gp"), frf_plot_script(*p.frf, p.scenario.inputs[static_cast<std::size_t>(p.frf_input)].name,
                                                              plot_title(r), "fit.csv", "fit.png"));
    render("fit.png", render_gnuplot(dir.staging(), "fit.gp"));
    io::write_json_atomic(dir.path("identify.json"), r.to_json(p));
    return;
  }
  // fit.csv: measured, predicted and residual per sensor at the sample times.
  const MatrixXd predicted = predicted_outputs(p, r);
  const io::DataTable tab = fit_table(p.data, predicted);
  io::write_csv(dir.path("fit.csv"), tab);
  // fit.gp, rendered to fit.png when gnuplot is installed (the script stays for other terminals).
  std::vector<std::pair<int, double>> cost;
  for (const auto& it : r.summary.iterations) cost.emplace_back(it.k, it.cost);
  FitPlotAnnotations notes;
  notes.title = plot_title(r);
  notes.units = sensor_units(p);
  std::tie(notes.zoom_from, notes.zoom_to) = zoom_window(p.data);
  io::write_text_atomic(dir.path("fit.gp"), fit_plot_script(p.data.names, cost, "fit.csv", "fit.png", notes));
  std::vector<std::string> scripts;
  if (write_spectrum(dir, p, r, predicted, notes.title)) scripts.push_back("spectrum.gp");
  if (write_start_frf(dir, p, r)) scripts.push_back("start_frf.gp");
  // fit.png (from a raw float64 copy of fit.csv: the same numbers, no text to parse) and
  // spectrum.png rendered side by side.
  const std::vector<RenderStatus> rendered =
      render_fit_plots(dir.staging(), {FitPlot{&tab, p.data.names, cost, "fit.png", notes}}, scripts);
  for (std::size_t i = 0; i < rendered.size(); ++i)
    render(i == 0 ? "fit.png" : scripts[i - 1] == "spectrum.gp" ? "spectrum.png" : "start_frf.png", rendered[i]);
  io::write_json_atomic(dir.path("identify.json"), r.to_json(p));
}

}  // namespace scoleid::identify
