// One identification run (identify_run.h): the stages in order — strategy (run/strategy.h),
// attempts (run/attempts.h), assessment (run/assessment.h); the outputs: run/run_report.cpp.
#include "scoleid/identify/run/identify_run.h"

#include "scoleid/identify/fe/lowest_modes.h"

#include "scoleid/identify/door/run_door.h"
#include "scoleid/identify/point_failure.h"
#include "scoleid/io/progress.h"

#include <stdexcept>
#include <csignal>
#include <cstdio>
#include <chrono>
#include <algorithm>
#include <cmath>
#include <exception>
#include <thread>

#include "scoleid/identify/inverse/tied_parameterization.h"
#include "scoleid/identify/run/assessment.h"
#include "scoleid/identify/run/attempts.h"
#include "scoleid/identify/run/frf_run.h"
#include "scoleid/identify/run/strategy.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/limits.h"

namespace scoleid::identify {

double model_error(const Problem& p) {
  const double m = p.scenario.identification.model_error;
  if (m >= 0) return m;
  const bool own_model = p.origin == Problem::DataOrigin::Synthesis && !io::has_truth_overrides(p.scenario);
  return own_model ? 0.0 : 0.01;
}

FitTest test_fit(const Problem& p, Objective& obj, const VectorXd& q, const MatrixXd* discretisation,
                 const std::function<void()>& meanwhile) {
  FitTestInputs in;
  in.data = p.data.z;
  in.names = p.data.names;
  in.noise_std = p.noise_std;
  in.noise_origin = p.noise_origin;
  in.model_error = model_error(p);
  in.independent_fraction = p.band_gain;
  if (!q.allFinite()) {
    in.residual = MatrixXd::Constant(in.data.rows(), in.data.cols(), std::nan(""));
    return fit_test(in);
  }
  // The identifier's outputs at q (on this thread) and, when no estimate is given, the refined
  // model's (on a second one: the two solves are independent).
  MatrixXd Y, Yfine;
  auto own = [&] {
    try {
      Y = obj.predict(q);
    } catch (const std::exception& e) {
      if (!point_failure(e)) throw;
      Y = MatrixXd::Constant(in.data.rows(), in.data.cols(), std::nan(""));  // not explained
    }
  };
  // The discretisation estimate: the same model on twice the elements at a quarter of the step (the
  // refinement the synthetic data are made with, problem.h), when that fits the limits.
  const int fine_elements = 2 * p.structure->elements();
  const double T = p.data.t.back() - p.data.t.front();
  const double h = p.objective_options.solver.step > 0 ? p.objective_options.solver.step / 4.0 : T / 8000.0;
  const double bytes = (T / h + 1.0) * 2.0 * p.model().ndof * 3.0 * 8.0;
  if (!discretisation && fine_elements <= io::limits::kMaxDataElements && bytes <= io::limits::kMaxTrajectoryBytes) {
    std::exception_ptr fine_error;
    std::thread refined([&] {
      try {
        const auto fine = make_structure(p.scenario, fine_elements);
        const auto params = fine->parameterize(p.scenario);
        if (params->names() == p.params->names()) {
          ObjectiveOptions o = p.objective_options;
          if (o.solver.step > 0) o.solver.step /= 4.0;
          Objective fo(fine->model(), *params, p.signals, p.data, o);
          Yfine = fo.predict(q);
        }
      } catch (const std::exception& e) {
        // Where the finer model cannot be evaluated at q: no discretisation estimate. Anything
        // else (an interrupt; an input the door let through, a defect) reaches the caller.
        if (point_failure(e)) return;
        fine_error = std::current_exception();
      }
    });
    try {
      own();
      if (meanwhile) meanwhile();
    } catch (...) {
      refined.join();
      throw;
    }
    refined.join();
    if (fine_error) std::rethrow_exception(fine_error);
    if (Y.allFinite() && Yfine.rows() == Y.rows() && Yfine.cols() == Y.cols()) {
      MatrixXd d = Yfine - Y;
      if (d.allFinite()) in.discretisation = std::move(d);
    }
  } else {
    own();
    if (discretisation && discretisation->rows() == Y.rows() && discretisation->cols() == Y.cols())
      in.discretisation = *discretisation;
  }
  in.residual = Y - p.data.z;
  FitTest f = fit_test(in);
  f.discretisation = std::move(in.discretisation);
  f.predicted = std::move(Y);
  return f;
}

bool better_attempt(const RunResult::Attempt& a, const RunResult::Attempt& b, long data_values) {
  const int ra = (a.optimizer_converged && a.explains_data ? 2 : 0) + (a.explains_data ? 1 : 0);
  const int rb = (b.optimizer_converged && b.explains_data ? 2 : 0) + (b.explains_data ? 1 : 0);
  if (ra != rb) return ra > rb;
  // Lower by more than fitting one more free parameter to the noise would gain (J/N): two runs that
  // ended at the same minimum differ by rounding, and the earlier one is kept.
  const double margin = data_values > 0 && std::isfinite(b.cost) ? b.cost / static_cast<double>(data_values) : 0.0;
  return a.cost < b.cost - margin;
}

void estimate_modes(const Problem& p, RunResult& r, bool verbose) {
  if (!r.estimate.allFinite()) return;
  if (verbose && p.model().ndof >= kSparseModesFrom && !sparse_modes_pay(p.model().ndof, ModalUncertaintyOptions{}.max_modes + 7))
    io::progress("modes of the identified model: %ld dense eigen-solutions of the %d-degree-of-freedom model (each about %.2g s, "
                 "O(n^3); fewer elements are faster)\n",
                 1L + (r.ident.std.size() == r.estimate.size() ? 2L * static_cast<long>(r.estimate.size()) : 0L), p.model().ndof,
                 dense_eigen_seconds(p.model().ndof, true));
  ModalUncertaintyOptions o;
  // Modes above the data's Nyquist frequency are not seen by the record (its median sample interval),
  // nor modes above the top line of FRFs.
  if (p.frf) {
    o.max_frequency_hz = p.frf->f_hz.back();  // the FRFs' top line
  } else if (p.data.t.size() >= 2) {
    std::vector<double> dt(p.data.t.size() - 1);
    for (std::size_t i = 0; i + 1 < p.data.t.size(); ++i) dt[i] = p.data.t[i + 1] - p.data.t[i];
    std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
    if (dt[dt.size() / 2] > 0) o.max_frequency_hz = 0.5 / dt[dt.size() / 2];
  }
  if (!r.record_modes.modes.empty()) o.record = &r.record_modes;
  try {
    r.modes = modal_estimates(p.model(), *p.params, r.estimate, r.ident, r.interval, o);
  } catch (const std::exception& e) {
    if (!point_failure(e)) throw;
    r.modes.clear();  // a model without a modal decomposition at the estimate: no modes reported
  }
}

RunResult start_result(const Problem& p, io::Model model) {
  RunResult r;
  r.model = model;
  r.scenario = p.scenario.name;
  r.names = p.params->names();
  r.initial = p.params->initial();
  r.truth = p.true_values;
  return r;
}

namespace {
// The smoothness prior's chains (identification.smoothness, docs/theory.md §7.8): the sectional
// families, refused for a run without sections.
std::vector<std::vector<int>> smoothness_chains(const Problem& p, const std::vector<std::string>& names) {
  if (p.scenario.identification.smoothness == 0.0) return {};
  auto chains = section_families(names);
  if (chains.empty()) throw std::logic_error("smoothness_chains: no sectional family (identify::check_run refuses it)");
  return chains;
}
}  // namespace

namespace {
// An interrupted run's result (RunOptions::keep_interrupted): the chosen estimate when the attempts
// had ended (the assessment was under way), else the last iterate accepted; not assessed, no fit
// test (so not converged), the signal recorded and cleared so that the outputs can be made.
void keep_interrupted(const Problem& p, const AttemptsContext& c, RunResult& r, bool attempts_done, int signal) {
  io::clear_interrupt();
  const char* what = signal == SIGALRM ? "the wall-time limit" : signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : "a signal";
  char note[256];
  if (attempts_done) {
    std::snprintf(note, sizeof note, "%s during the assessment: the estimate is the optimiser's (%s), not assessed", what,
                  to_string(r.summary.termination));
  } else {
    const IterationRecord& last = c.iterates.back();
    r.summary.iterations = c.iterates;
    r.summary.q = last.q;
    r.summary.cost = last.cost;
    r.summary.iterations_done = last.k;
    std::snprintf(note, sizeof note, "%s at iteration %d: the last iterate reached (its cost over %.6g of %.6g s of record), not converged",
                  what, last.k, last.horizon - p.data.t.front(), p.data.t.back() - p.data.t.front());
  }
  r.summary.termination = OptimizerSummary::Termination::Interrupted;
  r.summary.message = note;
  r.estimate = r.summary.q;
  r.fit = FitTest{};
  r.fit.message = std::string("not tested: ") + note;
  r.ident = Identifiability{};
  r.interval = UncertaintyInterval{};
  r.predicted.resize(0, 0);
  r.interrupted_by = signal;
  r.interrupted_note = note;
}
}  // namespace

RunResult run_identification(Problem& p, const RunOptions& ro) {
  check_run(p, ro);
  if (p.scenario.identification.model == io::Model::Nonlinear) return run_nonlinear_identification(p, ro);
  if (p.frf) return run_frf_identification(p, ro);
  const auto t0 = std::chrono::steady_clock::now();
  const auto& id = p.scenario.identification;
  RunResult r = start_result(p, io::Model::Linear);
  Objective obj(p.model(), *p.params, p.signals, p.data, p.objective_options);
  r.method = resolve_method(ro.method.value_or(id.method), p.params->size(), id.smoothness != 0.0,
                            obj.has_matrix_free_products());
  if (r.method == io::Method::GaussNewtonKrylov && !obj.has_matrix_free_products())
    throw std::logic_error("run_identification: gauss-newton-krylov without matrix-free products (identify::check_run refuses it)");
  const auto chains = smoothness_chains(p, r.names);
  AttemptsContext c{p, obj, optimizer_options(id, r.method, p.params->size(), ro.max_iterations), ro.verbose, {}, {}};
  c.options.smoothness_chains = chains;
  // The assessment's refits (ro.compute_std) at the first attempt's estimate, made while its fit
  // test's doubled-mesh solve runs (AttemptsContext::alongside_fit), kept if that estimate stands.
  IntervalInputs early;
  if (ro.compute_std)
    c.alongside_fit = [&](const VectorXd& q) {
      try {
        early = assessment_refits(p, obj, c.options, q, 1);  // one core: the other solves the doubled mesh
      } catch (const std::exception& e) {
        if (!point_failure(e)) throw;
        early = {};  // made again, if needed, in the assessment
      }
    };
  bool attempts_done = false;
  try {
    run_attempts(c, r);
    attempts_done = true;
    r.estimate = r.summary.q;
    // The fit test's outputs at the estimate (the chosen attempt's), kept for the assessment and fit.csv.
    if (r.fit.predicted.rows() == p.data.z.rows() && r.fit.predicted.cols() == p.data.z.cols() && r.fit.predicted.allFinite())
      r.predicted = r.fit.predicted;
    if (ro.compute_std) assess_estimate(p, obj, c.options, r, early.estimate.size() != 0 ? &early : nullptr);
  } catch (const io::Interrupted& e) {
    if (!ro.keep_interrupted || (!attempts_done && c.iterates.empty())) throw;
    keep_interrupted(p, c, r, attempts_done, e.signal());
    r.summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  estimate_modes(p, r, ro.verbose);
  if (obj.estimates_initial_state() && r.estimate.size() == p.params->size()) {
    for (Eigen::Index j = 0; j < obj.initial_state_omega().size(); ++j)
      r.initial_state_hz.push_back(obj.initial_state_omega()[j] / (2.0 * M_PI));
    try {
      r.initial_state_coefficients = obj.initial_state_coefficients(r.estimate);
    } catch (const std::domain_error&) {
      r.initial_state_coefficients = {};  // an estimate outside the positive range (an interrupted run's)
    }
  }
  if (r.predicted.size() != 0) r.residual_bands = residual_bands(p.data.t, p.data.z, r.predicted, r.modes, r.fit.explains_data);
  r.counters = obj.counters();
  r.counters.Accumulate(c.extra);
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace scoleid::identify
