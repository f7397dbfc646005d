// Several experiments identified together (experiments.h; docs/theory.md §6.5).
#include "scoleid/identify/run/experiments.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <stdexcept>

#include "scoleid/identify/door/run_door.h"
#include "scoleid/identify/inverse/frf_misfit.h"
#include "scoleid/identify/inverse/joint_misfit.h"
#include "scoleid/identify/inverse/modal_misfit.h"
#include "scoleid/identify/point_failure.h"
#include "scoleid/identify/run/assessment.h"
#include "scoleid/identify/run/fit_plot.h"
#include "scoleid/identify/run/frf_run.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/identify/run/strategy.h"
#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/output_paths.h"
#include "scoleid/io/progress.h"
#include "scoleid/io/validation.h"

namespace scoleid::identify {

bool ExperimentsResult::converged() const {
  if (!summary.converged()) return false;
  for (const auto& e : experiments)
    if (!e.explains_data) return false;
  return true;
}

namespace {

// A run's fit test in its experiment's entry: the verdict, its message, each channel's residual RMS.
void take_fit(const FitTest& f, ExperimentsResult::Experiment& x) {
  x.explains_data = f.explains_data;
  x.fit_message = f.message;
  for (const auto& s : f.sensors) {
    x.channels.push_back(s.name);
    x.residual_rms.push_back(s.rms_residual);
  }
}

// A time run's part of the joint result at the estimate: its fit test, residual RMS per sensor and,
// with compute_std, its own Fisher information.
FisherInformation time_experiment(Problem& p, Objective& obj, const VectorXd& estimate, bool compute_std,
                                  ExperimentsResult::Experiment& x) {
  FisherInformation fi;
  x.kind = "time";
  x.data_source = p.data_source;
  x.data_values = static_cast<long>(p.data.t.size()) * p.data.sensors();
  take_fit(test_fit(p, obj, estimate), x);
  if (compute_std) {
    fi = fisher_information(obj, sensors_with_noise(p), estimate);
  }
  x.counters = obj.counters();
  return fi;
}

// A frequency-domain run's part at the estimate: its fit test (frf_run.h), residual RMS per channel
// (in the FRF's unit) and, with compute_std, its Fisher information.
FisherInformation frf_experiment(Problem& p, FrfMisfit& m, const VectorXd& estimate, bool compute_std,
                                 ExperimentsResult::Experiment& x) {
  FisherInformation fi;
  x.kind = "frf";
  x.data_source = p.data_source;
  x.data_values = 2L * p.frf->lines() * static_cast<long>(p.frf->channels.size());
  take_fit(frf_fit_test(p, m, estimate), x);
  if (compute_std) fi = frf_fisher(m, estimate);
  x.factorisations = m.counters().factorisations;
  return fi;
}

// The modal data's part: χ² against its degrees of freedom, and its Fisher information.
FisherInformation modal_experiment(ModalMisfit& modal, const io::ModalData& modes, const std::string& file, int components,
                                   int parameters, const VectorXd& estimate, bool compute_std,
                                   ExperimentsResult::Experiment& x) {
  FisherInformation fi;
  x.kind = "modal";
  x.data_source = file;
  VectorXd res;
  modal.residuals(estimate, res);
  const auto N = static_cast<double>(res.size());
  x.data_values = static_cast<long>(res.size());
  const double chi2 = res.squaredNorm();
  // Degrees of freedom: a unit-normalised shape's residual has one component fewer than its
  // stations (it is orthogonal to the shape to first order); with the modes the only data the
  // P fitted parameters take P more.
  const double shapes = modes.has_shapes() ? static_cast<double>(modes.modes.size()) : 0.0;
  const double nu = std::max(1.0, N - shapes - (components == 1 ? static_cast<double>(parameters) : 0.0));
  x.explains_data = chi2 <= nu + 3.0 * std::sqrt(2.0 * nu);
  char buf[240];
  std::snprintf(buf, sizeof buf, "chi2 %.4g over %ld modal residuals, %.0f degrees of freedom (band up to %.4g)%s", chi2,
                x.data_values, nu, nu + 3.0 * std::sqrt(2.0 * nu),
                x.explains_data ? "" : ": the modes are not explained within their stated uncertainties");
  x.fit_message = buf;
  x.channels.push_back("all (in stated stds)");
  x.residual_rms.push_back(N > 0 ? std::sqrt(chi2 / N) : 0.0);
  if (compute_std) {
    fi.F = modal.fisher(estimate);
    fi.chi2 = chi2;
    fi.data_values = x.data_values;
    fi.systematic = std::max(0.0, chi2 - nu - 2.0 * std::sqrt(2.0 * nu));
    fi.stated_noise = true;
    fi.noise_std.clear();
  }
  return fi;
}

// Measured modes alone: the interval from the noise (the file's stds) and residual terms of the
// Fisher information (no half-record refit applies to a mode set; docs/theory.md §8.2), a parameter
// whose interval exceeds half its value flagged as the time-domain assessment flags it.
void modal_interval(ExperimentsResult& r, const ExperimentsProblem& ep) {
  IntervalInputs in;
  in.estimate = r.estimate;
  in.refit_applies = false;
  r.interval = uncertainty_interval(r.ident, in);
  r.interval.note = "measured modes alone: noise (the file's stds) and residual terms only, no half-record refit";
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    if (!r.ident.identifiable[i] || !r.interval.too_wide[i]) continue;
    r.ident.identifiable[i] = false;
    char buf[200];
    std::snprintf(buf, sizeof buf, "uncertainty interval ±%.3g is %.3g of the estimate: above 0.5 (the modes determine it only with others)",
                  r.interval.half_width[e], r.interval.half_width[e] / std::abs(r.estimate[e]));
    r.ident.reason[i] = buf;
  }
}

}  // namespace

// The optimiser's callback: a signal ends the run; with `verbose` a table row per iteration (the
// header printed now).
static std::function<void(const IterationRecord&)> progress_printer(const std::vector<std::string>& names, bool verbose) {
  if (verbose) {
    io::progress("%5s", "iter");
    for (std::size_t i = 0; i < names.size() && i < 6; ++i) io::progress(" %13s", names[i].c_str());
    io::progress(" %13s %8s\n", "cost", "horizon");
  }
  return [verbose](const IterationRecord& rec) {
    io::check_interrupt();
    if (!verbose) return;
    io::progress("%5d", rec.k);
    for (Eigen::Index i = 0; i < rec.q.size() && i < 6; ++i) io::progress(" %13.6g", rec.q[i]);
    io::progress(" %13.6e %8.4g\n", rec.cost, rec.horizon);
    std::fflush(stdout);
  };
}

// Each experiment's cost, share and (with compute_std) its own and the joint Fisher information.
static void assess_experiments(ExperimentsProblem& ep, const ExperimentsOptions& eo, JointMisfit& joint,
                               const std::vector<std::unique_ptr<Objective>>& objs,
                               const std::vector<std::unique_ptr<FrfMisfit>>& frfs, ModalMisfit* modal, int P, double J,
                               ExperimentsResult& r) {
  FisherInformation total;
  for (int e = 0; e < joint.components(); ++e) {
    ExperimentsResult::Experiment x;
    x.name = joint.name(e);
    x.cost = joint.last_costs()[static_cast<std::size_t>(e)];
    x.share = J > 0 ? x.cost / J : 0.0;
    const auto u = static_cast<std::size_t>(e);
    const FisherInformation fi =
        e >= static_cast<int>(ep.runs.size())
            ? modal_experiment(*modal, *ep.modes, *ep.spec.modes_file, joint.components(), P, r.estimate, eo.compute_std, x)
        : frfs[u] ? frf_experiment(*ep.runs[u], *frfs[u], r.estimate, eo.compute_std, x)
                  : time_experiment(*ep.runs[u], *objs[u], r.estimate, eo.compute_std, x);
    if (eo.compute_std) {
      x.alone = identifiability_from(fi, r.estimate);
      if (x.kind == "modal") x.alone.noise_source = "the modal data file's stds";
      if (x.kind == "frf") x.alone.noise_source = "frf";
      total += fi;
    }
    r.experiments.push_back(std::move(x));
  }
  if (eo.compute_std) {
    r.ident = identifiability_from(total, r.estimate);
    if (r.weighting == "relative")
      r.std_note = "some noise levels are not stated: the runs are weighed by their relative misfit, not by the likelihood, "
                   "so the std (the Cramér-Rao bound with noise levels from the residual) may be optimistic";
    if (ep.runs.empty() && ep.modes) modal_interval(r, ep);
  }
}

ExperimentsResult run_experiments(ExperimentsProblem& ep, const ExperimentsOptions& eo) {
  check_experiments_run(ep, eo);
  const auto t_start = std::chrono::steady_clock::now();
  ExperimentsResult r;
  r.name = ep.spec.name;
  const io::Scenario& lead = ep.runs.empty() ? *ep.modes_scenario : ep.runs.front()->scenario;
  const Parameterization& params = ep.runs.empty() ? *ep.modes_params : *ep.runs.front()->params;
  r.names = params.names();
  r.initial = params.initial();
  // The true values where the data's origin states them (synthetic runs, truth.json beside a data
  // file); measured modes carry none.
  if (!ep.runs.empty()) r.truth = ep.runs.front()->true_values;
  // Likelihood weights where the door set them (every time run's noise stated, experiments_door.cpp);
  // frequency-domain runs and modal data are ½χ² of stated variances anyway.
  r.weighting = "likelihood";
  for (const auto& p : ep.runs)
    if (!p->frf && p->objective_options.weights.empty()) r.weighting = "relative";

  // One misfit per run: a time-domain Objective or a frequency-domain FrfMisfit (the other slot null).
  std::vector<std::unique_ptr<Objective>> objs;
  std::vector<std::unique_ptr<FrfMisfit>> frfs;
  std::vector<JointMisfit::Component> parts;
  // Several parts are already solved side by side: one thread per sweep or pass over the lines.
  const bool several = ep.runs.size() + (ep.modes ? 1 : 0) > 1;
  for (std::size_t i = 0; i < ep.runs.size(); ++i) {
    Problem& p = *ep.runs[i];
    if (p.frf) {
      FrfMisfitOptions fo;
      if (several) fo.threads = 1;
      objs.emplace_back();
      frfs.push_back(std::make_unique<FrfMisfit>(p.model(), *p.params, *p.frf, p.frf_sensors, p.frf_input, fo));
      parts.push_back({ep.spec.runs[i].name, frfs.back().get()});
      continue;
    }
    ObjectiveOptions oo = p.objective_options;
    if (several) oo.sweep_threads = 1;
    objs.push_back(std::make_unique<Objective>(p.model(), *p.params, p.signals, p.data, oo));
    frfs.emplace_back();
    parts.push_back({ep.spec.runs[i].name, objs.back().get()});
  }
  std::unique_ptr<ModalMisfit> modal;
  if (ep.modes) {
    modal = std::make_unique<ModalMisfit>(ep.modes_structure->model(), *ep.modes_params, *ep.modes);
    parts.push_back({"modes", modal.get()});
  }
  JointMisfitOptions jo;
  jo.threads = eo.threads.value_or(ep.spec.threads);
  JointMisfit joint(parts, jo);
  r.threads = joint.threads();

  // A joint run takes no smoothness prior (refused by make_experiments).
  r.method = resolve_method(eo.method.value_or(lead.identification.method), params.size(), false,
                            joint.has_matrix_free_products());
  if (r.method == io::Method::GaussNewtonKrylov && !joint.has_matrix_free_products())
    throw std::logic_error("run_experiments: gauss-newton-krylov without matrix-free products (check_experiments_run refuses it)");
  const OptimizerOptions oo = optimizer_options(lead.identification, r.method, params.size(), eo.max_iterations);
  const auto progress = progress_printer(r.names, eo.verbose);
  r.summary = minimize(joint, r.initial, oo, progress);
  r.estimate = r.summary.q;
  joint.set_horizon(1.0);
  double J = 0.0;
  try {
    J = joint.cost(r.estimate);
  } catch (const std::exception& e) {
    if (!point_failure(e)) throw;
    throw std::runtime_error("the model cannot be evaluated at the estimate (" + io::one_line(e.what()) + ")");
  }
  r.summary.cost = J;

  assess_experiments(ep, eo, joint, objs, frfs, modal.get(), params.size(), J, r);
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return r;
}

// The joint run's interval per parameter (the interval of a modal-data run), or why there is none.
static nlohmann::json interval_json(const ExperimentsResult& r) {
  using nlohmann::json;
  if (r.interval.half_width.size() != r.estimate.size())
    return "not assessed in a joint run with records (no half-record or half-band refit, no consider terms): std and "
           "resolution are the Fisher information's of all experiments together";
  auto finite = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  json iv = json::object();
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const double w = r.interval.half_width[e];
    json x{{"half_width", finite(w)},
           {"low", std::isfinite(w) ? json(r.estimate[e] - w) : json(nullptr)},
           {"high", std::isfinite(w) ? json(r.estimate[e] + w) : json(nullptr)},
           {"noise_2std", finite(r.interval.noise[e])},
           {"residual_2resolution", finite(r.interval.residual[e])}};
    if (const auto t = r.truth.find(r.names[i]); t != r.truth.end() && std::isfinite(w))
      x["covers_truth"] = std::abs(r.estimate[e] - t->second) <= w;
    iv[r.names[i]] = x;
  }
  return iv;
}

nlohmann::json ExperimentsResult::to_json() const {
  using nlohmann::json;
  auto finite = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  auto per_param = [&](const VectorXd& v) {
    json o = json::object();
    for (std::size_t i = 0; i < names.size(); ++i)
      o[names[i]] = static_cast<Eigen::Index>(i) < v.size() ? finite(v[static_cast<Eigen::Index>(i)]) : json(nullptr);
    return o;
  };
  auto ident_json = [&](const Identifiability& id) {
    if (id.identifiable.empty()) return json{{"assessed", false}};
    json flags = json::object();
    for (std::size_t i = 0; i < names.size(); ++i) flags[names[i]] = id.identifiable[i] ? json(true) : json(id.reason[i]);
    return json{{"assessed", true},        {"std", per_param(id.std)},     {"resolution", per_param(id.resolution)},
                {"identifiable", flags},    {"condition_number", finite(id.condition_number)},
                {"chi2", id.chi2},          {"data_values", id.data_values}, {"noise_source", id.noise_source}};
  };
  json out;
  out["experiments"] = name;
  out["method"] = io::to_string(method);
  out["weighting"] = weighting;
  out["threads"] = threads;
  out["converged"] = converged();
  out["optimizer_converged"] = summary.converged();
  out["termination"] = to_string(summary.termination);
  out["message"] = summary.message;
  out["iterations"] = summary.iterations_done;
  out["cost"] = summary.cost;
  out["initial"] = per_param(initial);
  out["estimate"] = per_param(estimate);
  json t = json::object();
  for (const auto& [k, v] : truth) t[k] = v;
  out["truth"] = t;
  out["identifiability"] = ident_json(ident);
  if (!ident.identifiable.empty()) {
    out["identifiability"]["std_note"] = std_note;
    out["identifiability"]["interval"] = interval_json(*this);
    if (interval.half_width.size() == estimate.size()) out["identifiability"]["interval_note"] = interval.note;
  }
  json ex = json::array();
  for (const auto& e : experiments) {
    json rms = json::object();
    for (std::size_t k = 0; k < e.channels.size(); ++k) rms[e.channels[k]] = finite(e.residual_rms[k]);
    ex.push_back({{"name", e.name},
                  {"kind", e.kind},
                  {"data", e.data_source},
                  {"cost", e.cost},
                  {"misfit_share", e.share},
                  {"data_values", e.data_values},
                  {"residual_rms", rms},
                  {"explains_data", e.explains_data},
                  {"fit_message", e.fit_message},
                  {"alone_at_joint_estimate", ident_json(e.alone)},
                  {"solves", e.kind == "frf" ? json{{"factorisations", e.factorisations}}
                                             : json{{"forward", e.counters.forward_solves},
                                                    {"costate", e.counters.costate_solves},
                                                    {"sensitivity", e.counters.sensitivity_solves}}}});
  }
  out["per_experiment"] = ex;
  json hist = json::array();
  for (const auto& it : summary.iterations) hist.push_back({{"k", it.k}, {"cost", it.cost}, {"q", per_param(it.q)}, {"horizon", it.horizon}});
  out["history"] = hist;
  out["wall_seconds"] = wall_seconds;
  return out;
}

std::vector<std::string> experiments_output_files(const ExperimentsSpec& spec) {
  std::vector<std::string> f = {"identify.json"};
  for (const auto& r : spec.runs)
    for (const char* ext : {".csv", ".gp", ".png"}) f.push_back("fit-" + r.name + ext);
  if (spec.modes_file) f.push_back("modes-fit.csv");
  return f;
}

void write_experiments_outputs(io::RunDirectory& dir, ExperimentsProblem& ep, const ExperimentsResult& r) {
  std::vector<std::pair<int, double>> cost;
  for (const auto& it : r.summary.iterations) cost.emplace_back(it.k, it.cost);
  std::vector<io::DataTable> tables(ep.runs.size());
  std::vector<FitPlot> plots;
  std::vector<std::string> frf_scripts;
  for (std::size_t i = 0; i < ep.runs.size(); ++i) {
    Problem& p = *ep.runs[i];
    const std::string base = "fit-" + ep.spec.runs[i].name;
    if (p.frf) {
      FrfMisfit m(p.model(), *p.params, *p.frf, p.frf_sensors, p.frf_input, FrfMisfitOptions{1});
      io::write_csv(dir.path(base + ".csv"), frf_fit_table(*p.frf, r.estimate.allFinite() ? m.predict(r.estimate) : Eigen::MatrixXcd()));
      io::write_text_atomic(dir.path(base + ".gp"),
                            frf_plot_script(*p.frf, p.scenario.inputs[static_cast<std::size_t>(p.frf_input)].name,
                                            r.name + ": " + ep.spec.runs[i].name, base + ".csv", base + ".png"));
      frf_scripts.push_back(base + ".gp");
      continue;
    }
    Objective obj(p.model(), *p.params, p.signals, p.data, p.objective_options);
    tables[i] = fit_table(p.data, obj.predict(r.estimate));
    io::write_csv(dir.path(base + ".csv"), tables[i]);
    io::write_text_atomic(dir.path(base + ".gp"), fit_plot_script(p.data.names, cost, base + ".csv", base + ".png"));
    plots.push_back(FitPlot{&tables[i], p.data.names, cost, base + ".png", {}});
  }
  // Every run's plot side by side, a time run's from a raw float64 copy of its table.
  const std::vector<RenderStatus> rendered = render_fit_plots(dir.staging(), plots, frf_scripts);
  for (std::size_t i = 0; i < rendered.size(); ++i)
    if (rendered[i] == RenderStatus::Failed)
      std::fprintf(stderr, "scole-identify: note: gnuplot could not render %s\n",
                   i < plots.size() ? plots[i].png.c_str() : frf_scripts[i - plots.size()].c_str());
  if (ep.modes) {
    ModalMisfit modal(ep.modes_structure->model(), *ep.modes_params, *ep.modes);
    const auto matches = modal.matches(r.estimate);
    const bool damping = ep.modes->has_damping(), shapes = ep.modes->has_shapes();
    std::string csv = "mode,frequency_hz_measured,frequency_hz_model,model_mode";
    if (shapes) csv += ",mac";
    csv += damping ? ",damping_ratio_measured,damping_ratio_model\n" : ",damping_ratio_model\n";
    char buf[400];
    for (const auto& m : matches) {
      const auto& meas = ep.modes->modes[static_cast<std::size_t>(m.measured)];
      std::snprintf(buf, sizeof buf, "%d,%.17g,%.17g,%d", meas.label, meas.frequency_hz, m.frequency_hz, m.model + 1);
      csv += buf;
      if (shapes) {
        std::snprintf(buf, sizeof buf, ",%.17g", m.mac);
        csv += buf;
      }
      if (damping) {
        std::snprintf(buf, sizeof buf, ",%.17g", meas.damping_ratio);
        csv += buf;
      }
      std::snprintf(buf, sizeof buf, ",%.17g\n", m.damping_ratio);
      csv += buf;
    }
    io::write_text_atomic(dir.path("modes-fit.csv"), csv);
  }
  io::write_json_atomic(dir.path("identify.json"), r.to_json());
}

}  // namespace scoleid::identify
