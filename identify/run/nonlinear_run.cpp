// identification.model: nonlinear (docs/theory.md §3.8, §6.7): the same run as identify_run.cpp's
// on the nonlinear SCOLE model — optimiser with horizon continuation, the fit test (its
// discretisation estimate from the nonlinear model on twice the elements at a quarter of the
// step), one cautious-continuation restart after a false convergence, the Fisher analysis (std,
// resolution, flags) from differenced output sensitivities, and the uncertainty interval of
// interval.h from those and the half-record refit. Declared uncertainties (consider terms) are not
// propagated through this model: with any declared, it gives no interval and says so.
#include <stdexcept>
#include <chrono>
#include "scoleid/identify/point_failure.h"
#include <cmath>
#include <cstdio>
#include <tuple>

#include "scoleid/identify/inverse/nonlinear_objective.h"
#include "scoleid/identify/run/assessment.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/identify/run/strategy.h"
#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/progress.h"

namespace scoleid::identify {

namespace {

FitTest nonlinear_fit(const Problem& p, NonlinearObjective& obj, const VectorXd& q, const NonlinearForwardOptions& fo,
                      MatrixXd& predicted) {
  FitTestInputs in;
  in.data = p.data.z;
  in.names = p.data.names;
  in.noise_std = p.noise_std;
  in.noise_origin = p.noise_origin;
  in.model_error = model_error(p);
  predicted = MatrixXd::Constant(in.data.rows(), in.data.cols(), std::nan(""));
  obj.set_horizon(obj.data_end());
  if (q.allFinite()) {
    try {
      predicted = obj.predict(q);
    } catch (const std::exception& e) {
      if (!point_failure(e)) throw;
      // not explained
    }
  }
  in.residual = predicted - p.data.z;
  const int fine_elements = 2 * p.structure->elements();
  if (predicted.allFinite() && fine_elements <= io::limits::kMaxDataElements) {
    try {
      const ScoleNonlinear fine = scole_nonlinear(p.scenario, fine_elements);
      NonlinearForwardOptions ff = fo;
      ff.max_step = fo.max_step / 4.0;
      NonlinearObjective fobj(fine, *p.params, p.signals, p.data, ff);
      const MatrixXd d = fobj.predict(q) - predicted;
      if (d.allFinite()) in.discretisation = d;
    } catch (const std::exception& e) {
      if (!point_failure(e)) throw;
      // no discretisation estimate
    }
  }
  return fit_test(in);
}

// One nonlinear run's model, objective and table.
struct NonlinearRun {
  const Problem& p;
  const ScoleNonlinear model;
  NonlinearForwardOptions fo;
  NonlinearObjective obj;
  bool verbose;
  RunResult& r;
  NonlinearRun(const Problem& problem, const NonlinearForwardOptions& options, bool verbose_, RunResult& result)
      : p(problem), model(scole_nonlinear(problem.scenario, problem.structure->elements())), fo(options),
        obj(model, *problem.params, problem.signals, problem.data, options), verbose(verbose_), r(result) {}

  void progress(const IterationRecord& rec) const {
    io::check_interrupt();
    if (!verbose) return;
    if (std::isfinite(rec.gradient_norm))
      io::progress("%4d  J = %.6e  |g| = %.3e  horizon %.4g", rec.k, rec.cost, rec.gradient_norm, rec.horizon);
    else  // (a run's last point, whose gradient nothing needed: optimizers.h)
      io::progress("%4d  J = %.6e  |g| not taken  horizon %.4g", rec.k, rec.cost, rec.horizon);
    for (std::size_t i = 0; i < r.names.size(); ++i) io::progress("  %s = %.7g", r.names[i].c_str(), rec.q[static_cast<Eigen::Index>(i)]);
    io::progress("\n");
    std::fflush(stdout);
  }

  // One attempt from the starting values; appended to r.attempts.
  std::tuple<OptimizerSummary, FitTest, MatrixXd> attempt(const std::string& label, const OptimizerOptions& o) {
    OptimizerSummary s = minimize(obj, r.initial, o, [this](const IterationRecord& rec) { progress(rec); });
    MatrixXd pred;
    const FitTest f = nonlinear_fit(p, obj, s.q, fo, pred);
    RunResult::Attempt a;
    a.strategy = label;
    a.method = o.method;
    a.termination = to_string(s.termination);
    a.optimizer_converged = s.converged();
    // J over the whole record from the fit test's prediction (a point whose forward run fails
    // has none: infinite cost, not an aborted run).
    obj.set_horizon(obj.data_end());
    a.cost = INFINITY;
    if (pred.allFinite()) {
      try {
        a.cost = obj.cost(s.q);
      } catch (const std::exception& e) {
        if (!point_failure(e)) throw;
      }
    }
    if (!std::isfinite(a.cost)) a.cost = INFINITY;
    a.iterations = s.iterations_done;
    a.explains_data = f.explains_data;
    a.fit_message = f.message;
    r.attempts.push_back(a);
    return std::make_tuple(s, f, pred);
  }

  // The plain attempt, and after a false convergence one with a cautious horizon continuation.
  void attempts(const OptimizerOptions& oo) {
    const auto& id = p.scenario.identification;
    std::tie(r.summary, r.fit, r.predicted) = attempt(std::string("plain ") + io::to_string(oo.method), oo);
    if (id.restarts > 0 && r.summary.converged() && !r.fit.explains_data) {
      const OptimizerOptions oc = cautious_continuation(oo, id);
      if (verbose) io::progress("fit test: %s\nrestart (cautious continuation)\n", r.fit.message.c_str());
      auto [s, f, pred] = attempt(cautious_continuation_label(oc), oc);
      if (better_attempt(r.attempts.back(), r.attempts.front())) {
        r.chosen_attempt = 1;
        r.summary = s;
        r.fit = f;
        r.predicted = pred;
      }
    }
    r.summary.cost = r.attempts[static_cast<std::size_t>(r.chosen_attempt)].cost;
    if (verbose) io::progress("fit test: %s\n", r.fit.message.c_str());
  }

  // Fisher information from differenced output sensitivities (2P forward runs), each sensor's
  // stated noise or, without one, its residual RMS (identifiability.h); the interval from it and
  // the half-record refit, unless uncertainties are declared (not propagated through this model).
  void assess(const OptimizerOptions& oo) {
    const auto ti = std::chrono::steady_clock::now();
    obj.set_horizon(obj.data_end());
    const FisherInformation fi = fisher_information(p.data, r.predicted, obj.output_sensitivities(r.estimate), sensors_with_noise(p));
    r.ident = identifiability_from(fi, r.estimate);
    r.ident.noise_source = noise_origin(p, r.ident.noise_source);
    if (!p.scenario.identification.uncertain.empty()) {
      r.interval.note =
          "no uncertainty interval: declared uncertainties (identification.uncertain) are not propagated through the "
          "nonlinear model (std and resolution from the Fisher matrix only)";
    } else {
      // The half-record refit (interval.h): the same fit on the first half of the record, from q̂.
      // (A record too short to halve into two samples gets none: the interval is then not assessed.)
      IntervalInputs ii;
      ii.estimate = r.estimate;
      if (const Measurements half_data = first_half(p.data); half_data.t.size() >= 2) {
        NonlinearObjective half(model, *p.params, p.signals, half_data, fo);
        half.set_horizon(half.data_end());
        OptimizerOptions oh = oo;
        oh.continuation = false;
        const OptimizerSummary s = minimize(half, r.estimate, oh, [&](const IterationRecord&) { io::check_interrupt(); });
        r.half_record_estimate = ii.half_record_estimate = s.q;
        r.half_record_converged = ii.half_record_converged = s.converged();
      }
      r.interval = uncertainty_interval(r.ident, ii);
      flag_wide_intervals(r);
    }
    r.identifiability_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - ti).count();
  }
};

}  // namespace

RunResult run_nonlinear_identification(Problem& p, const RunOptions& ro) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto& id = p.scenario.identification;
  RunResult r = start_result(p, io::Model::Nonlinear);
  // The nonlinear model has no matrix-free products and takes no smoothness prior.
  r.method = resolve_method(ro.method.value_or(id.method), p.params->size(), false, false);
  if (r.method == io::Method::GaussNewtonKrylov || id.smoothness != 0.0)
    throw std::logic_error("run_nonlinear_identification: a choice the nonlinear model has not (identify::check_run refuses it)");
  NonlinearForwardOptions fo;
  fo.max_step = p.objective_options.solver.step > 0 ? p.objective_options.solver.step : (p.data.t[1] - p.data.t[0]) / 4.0;
  NonlinearRun run(p, fo, ro.verbose, r);
  const OptimizerOptions oo = optimizer_options(id, r.method, p.params->size(), ro.max_iterations);
  if (ro.verbose)
    io::progress("nonlinear model: %d elastic DOFs, step %.4g s, %s\n", run.model.elastic(), fo.max_step, io::to_string(r.method));
  run.attempts(oo);
  r.estimate = r.summary.q;
  if (ro.compute_std && r.estimate.allFinite() && r.predicted.allFinite()) run.assess(oo);
  estimate_modes(p, r);  // the small-amplitude modes about the undeformed state
  if (r.predicted.size() != 0) r.residual_bands = residual_bands(p.data.t, p.data.z, r.predicted, r.modes, r.fit.explains_data);
  r.counters = run.obj.counters();
  r.integrator_step = fo.max_step;
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace scoleid::identify
