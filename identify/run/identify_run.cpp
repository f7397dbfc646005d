#include "scoleid/identify/run/identify_run.h"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "scoleid/identify/inverse/tied_parameterization.h"
#include "scoleid/io/data_files.h"
#include "scoleid/identify/run/fit_plot.h"
#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/scenario_fields.h"

namespace scoleid::identify {

namespace {

// Paper-style iteration table: iteration, parameters, physical values, cost.
class Table {
public:
  // The physical columns of the paper form: rho_A, EI and what q3 stands for (the beam's
  // Kelvin–Voigt c_kv; zeta where there is no q3).
  Table(const Parameterization& p, bool physical_columns)
      : p_(p), phys_(physical_columns),
        columns_{"rho_A", "EI", physical_columns && p.physical(p.initial()).count("c_kv") ? "c_kv" : "zeta"} {}
  void header() const {
    std::printf("%5s", "iter");
    const int P = std::min(p_.size(), kMaxCols);
    for (int i = 0; i < P; ++i) std::printf(" %13s", p_.names()[static_cast<std::size_t>(i)].c_str());
    if (p_.size() > kMaxCols) std::printf(" %5s", "...");
    if (phys_)
      for (const char* n : columns_) std::printf(" %13s", n);
    std::printf(" %13s %8s\n", "cost", "horizon");
  }
  void row(const IterationRecord& r) const {
    std::printf("%5d", r.k);
    const int P = std::min(p_.size(), kMaxCols);
    for (int i = 0; i < P; ++i) std::printf(" %13.6g", r.q[i]);
    if (p_.size() > kMaxCols) std::printf(" %5s", "");
    if (phys_) {
      const auto ph = p_.physical(r.q);
      for (const char* n : columns_) {
        const auto it = ph.find(n);
        std::printf(" %13.6g", it == ph.end() ? std::nan("") : it->second);
      }
    }
    std::printf(" %13.6e %8.4g\n", r.cost, r.horizon);
    std::fflush(stdout);
  }

private:
  static constexpr int kMaxCols = 8;
  const Parameterization& p_;
  bool phys_;
  std::array<const char*, 3> columns_;
};

double safe(double v) { return std::isfinite(v) ? v : 0.0; }

const char* integrator_name(SolverOptions::Integrator i) {
  switch (i) {
    case SolverOptions::Integrator::Esdirk: return "esdirk324l2sa";
    case SolverOptions::Integrator::EsdirkArkode: return "arkode-esdirk324l2sa";
    case SolverOptions::Integrator::Bdf: return "cvodes-bdf";
  }
  return "?";
}

// Consider terms (interval.h): for each declared tolerance, the bias of the least-squares
// estimate when the structure's value is θ + Δθ and the model's θ: F⁻¹ Gᵀ W G_θ Δθ, with G_θ Δθ
// the central difference of the model's outputs at q̂ (or the difference to the alternative model
// form), over the parameters the Fisher test kept. A quantity the outputs do not depend on at q̂
// (an estimated one: the parameters overwrite it) is refused.
// Y0 and G: the model's outputs and their sensitivities at q (the Fisher step's). `discretisation`:
// the fit test's estimate d of the identifier's discretisation error at q (empty: none).
std::vector<ConsiderTerm> consider_terms(const Problem& p, const Identifiability& id, const VectorXd& q, const MatrixXd& Y0,
                                         const MatrixXd& G, const MatrixXd& discretisation) {
  std::vector<ConsiderTerm> terms;
  const auto& uncertain = p.scenario.identification.uncertain;
  if (uncertain.empty() && discretisation.size() == 0) return terms;
  const int P = static_cast<int>(q.size()), ns = static_cast<int>(Y0.cols());
  std::vector<int> keep;
  for (int i = 0; i < P; ++i)
    if (std::isfinite(id.std[i])) keep.push_back(i);
  const auto K = static_cast<Eigen::Index>(keep.size());
  MatrixXd Gk(G.rows(), K);
  for (Eigen::Index a = 0; a < K; ++a) Gk.col(a) = G.col(keep[static_cast<std::size_t>(a)]);
  VectorXd w(G.rows());
  for (Eigen::Index r = 0; r < G.rows(); ++r) {
    const double sd = id.noise_std[static_cast<std::size_t>(r % ns)];
    w[r] = 1.0 / (sd * sd);
  }
  const MatrixXd F = Gk.transpose() * w.asDiagonal() * Gk;
  const Eigen::LDLT<MatrixXd> ldlt(F);
  auto flat = [&](const MatrixXd& Y) {  // row i*ns + k, as G
    VectorXd v(Y.size());
    for (Eigen::Index i = 0; i < Y.rows(); ++i)
      for (Eigen::Index k = 0; k < Y.cols(); ++k) v[i * ns + k] = Y(i, k);
    return v;
  };
  // The model's outputs at q̂ with the scenario changed (the same data, inputs and time step).
  auto outputs = [&](const io::Scenario& sc) {
    const auto st = make_structure(sc, sc.identification.elements);
    const auto params = st->parameterize(sc);
    Objective o(st->model(), *params, p.signals, p.data, p.objective_options);
    return flat(o.predict(q));
  };
  // The identifier's own discretisation (docs/theory.md §8.2): the refined model's outputs differ
  // from the identifier's by d at q̂, and the least-squares fit absorbs the part of d the
  // parameters can mimic — a bias the residual does not show. Taken at 2d, as the fit test's
  // allowance (the refined model's own error and the fit's redistribution of it).
  if (discretisation.rows() == Y0.rows() && discretisation.cols() == Y0.cols() && discretisation.allFinite() && K > 0) {
    ConsiderTerm t;
    t.field = "discretisation";
    t.value = static_cast<double>(p.structure->elements());
    t.delta = 0.0;
    const VectorXd d = 2.0 * flat(discretisation);
    const VectorXd sk = ldlt.solve(Gk.transpose() * (w.asDiagonal() * d));
    t.shift = VectorXd::Zero(P);
    for (Eigen::Index a = 0; a < K; ++a) t.shift[keep[static_cast<std::size_t>(a)]] = sk[a];
    if (t.shift.allFinite()) terms.push_back(t);
  }
  for (const auto& u : uncertain) {
    ConsiderTerm t;
    t.field = u.field;
    io::Scenario hi = p.scenario, lo = p.scenario;
    VectorXd d;
    if (u.is_switch) {
      *io::bool_field(hi, u.field) = u.alternative;
      t.value = *io::bool_field(lo, u.field) ? 1.0 : 0.0;
      t.delta = 1.0;
      d = outputs(hi) - flat(Y0);
    } else {
      double* vh = io::numeric_field(hi, u.field);
      double* vl = io::numeric_field(lo, u.field);
      t.value = *vh;
      t.delta = u.tolerance;
      *vh += u.tolerance;
      *vl -= u.tolerance;
      // Central where both sides are valid scenarios; one-sided at the edge of the valid range (a
      // sensor at the tip of the mast cannot move beyond it).
      std::optional<VectorXd> yh, yl;
      try { yh = outputs(hi); } catch (const io::InputError&) {}
      // A quantity that cannot be negative (a stiffness, a mass) is not moved through zero.
      const bool lo_valid = io::signed_field(u.field) || (t.value > 0 ? *vl > 0 : *vl >= 0);
      if (lo_valid) try { yl = outputs(lo); } catch (const io::InputError&) {}
      if (yh && yl) d = 0.5 * (*yh - *yl);
      else if (yh) d = *yh - flat(Y0);
      else if (yl) d = flat(Y0) - *yl;
      else
        io::fail_field(p.scenario.source, "identification.uncertain." + u.field,
                       "moves the scenario out of its valid range on both sides", io::format_value(u.tolerance));
    }
    if (!(d.squaredNorm() > 0) || !d.allFinite())
      io::fail_field(p.scenario.source, "identification.uncertain." + u.field,
                     d.allFinite() ? "does not change the model's outputs (an estimated quantity, or one the sensors do not depend on)"
                                   : "makes the model's response non-finite",
                     u.is_switch ? (u.alternative ? "true" : "false") : io::format_value(u.tolerance));
    const VectorXd sk = ldlt.solve(Gk.transpose() * (w.asDiagonal() * d));
    t.shift = VectorXd::Zero(P);
    for (Eigen::Index a = 0; a < K; ++a) t.shift[keep[static_cast<std::size_t>(a)]] = sk[a];
    terms.push_back(t);
  }
  return terms;
}

}  // namespace

double model_error(const Problem& p) {
  const double m = p.scenario.identification.model_error;
  if (m >= 0) return m;
  const bool own_model = p.data_source.rfind("synthetic", 0) == 0 && !io::has_truth_overrides(p.scenario);
  return own_model ? 0.0 : 0.01;
}

FitTest test_fit(const Problem& p, Objective& obj, const VectorXd& q) {
  FitTestInputs in;
  in.data = p.data.z;
  in.names = p.data.names;
  in.noise_std = p.noise_std;
  in.model_error = model_error(p);
  if (!q.allFinite()) {
    in.residual = MatrixXd::Constant(in.data.rows(), in.data.cols(), std::nan(""));
    return fit_test(in);
  }
  MatrixXd Y;
  try {
    Y = obj.predict(q);
  } catch (const io::Interrupted&) {
    throw;
  } catch (const std::exception&) {
    Y = MatrixXd::Constant(in.data.rows(), in.data.cols(), std::nan(""));  // not explained
  }
  in.residual = Y - p.data.z;
  // The discretisation estimate: the same model on twice the elements at a quarter of the step (the
  // refinement the synthetic data are made with, problem.h), when that fits the limits.
  const int fine_elements = 2 * p.structure->elements();
  const double T = p.data.t.back() - p.data.t.front();
  const double h = p.objective_options.solver.step > 0 ? p.objective_options.solver.step / 4.0 : T / 8000.0;
  const double bytes = (T / h + 1.0) * 2.0 * p.model().ndof * 3.0 * 8.0;
  if (Y.allFinite() && fine_elements <= io::limits::kMaxDataElements && bytes <= io::limits::kMaxTrajectoryBytes) {
    try {
      const auto fine = make_structure(p.scenario, fine_elements);
      const auto params = fine->parameterize(p.scenario);
      if (params->names() == p.params->names()) {
        ObjectiveOptions o = p.objective_options;
        if (o.solver.step > 0) o.solver.step /= 4.0;
        Objective fo(fine->model(), *params, p.signals, p.data, o);
        MatrixXd d = fo.predict(q) - Y;
        if (d.allFinite()) in.discretisation = std::move(d);
      }
    } catch (const io::Interrupted&) {
      throw;
    } catch (const std::exception&) {
      // A model that cannot be refined: no discretisation estimate.
    }
  }
  FitTest f = fit_test(in);
  f.discretisation = std::move(in.discretisation);
  return f;
}

namespace {

// The smoothness weight by the discrepancy principle (docs/theory.md §7.8): β from 1 down by
// factors of 10, each solve from the previous estimate, until the data misfit is within what the
// residual holds anyway: the noise's expected misfit E J = Σ_k c_k W, c_k = ½ R_k σ_k², W = E∫ñ²
// (Measurements::white_noise_integral: the data's interpolant of unit white noise), plus two of
// its standard deviations √(Σ_k c_k² V), V = Var ∫ñ² (white_noise_integral_variance: the weights
// R_k differ by sensor, so a few sensors can carry most of J and the band is wider than that of N
// equal terms); plus the floor of the fit test beyond noise, ½ Σ_k R_k ((2 d_k)² + (m z_k)²)(T − t0)
// (fit_test.h: the discretisation estimate d_k at the first weight's estimate and the declared
// model error m of the RMS signal z_k — a weight is chosen only if its fit would pass the fit
// test); plus the interpolation floor (Objective::interpolation_misfit at that estimate). That β
// (the largest meeting it) and its estimate are kept. The stated noise levels are needed.
OptimizerSummary discrepancy_path(const Problem& p, Objective& obj, RunResult& r, const VectorXd& start, OptimizerOptions oo,
                                  const std::function<void(const IterationRecord&)>& progress, bool verbose) {
  double expected = 0.0, variance = 0.0;
  const auto& R = obj.weights();
  const double W = p.data.white_noise_integral(obj.data_start(), obj.data_end());
  const double V = p.data.white_noise_integral_variance(obj.data_start(), obj.data_end());
  for (std::size_t k = 0; k < R.size(); ++k) {
    const double sd = k < p.noise_std.size() ? p.noise_std[k] : 0.0;
    if (!(sd > 0.0))
      io::fail_field(p.scenario.source, "identification.smoothness",
                     "discrepancy needs every sensor's noise level stated (sensor '" + p.data.names[k] + "' has none)", "discrepancy");
    const double c = 0.5 * R[k] * sd * sd;
    expected += c * W;
    variance += c * c * V;
  }
  expected += 2.0 * std::sqrt(variance);
  r.smoothness_expected_misfit = expected;
  VectorXd q = start;
  OptimizerSummary chosen;
  bool have = false;
  bool floor_added = false;
  for (double beta = 1.0; beta >= 1e-10; beta /= 10.0) {
    oo.smoothness_weight = beta;
    OptimizerSummary s = minimize(obj, q, oo, progress);
    const double misfit = s.cost - s.prior_cost;
    if (!floor_added && s.q.allFinite()) {
      floor_added = true;
      const FitTest f = test_fit(p, obj, s.q);
      const double span = obj.data_end() - obj.data_start();
      double floor = 0.0;
      for (std::size_t k = 0; k < R.size() && k < f.sensors.size(); ++k) {
        // The fit test's allowance beyond noise (fit_test.h): (2 d_k)² + (m z_k)².
        const double d = std::isfinite(f.sensors[k].discretisation) ? f.sensors[k].discretisation : 0.0;
        const double m = f.model_error * f.sensors[k].rms_signal;
        floor += 0.5 * R[k] * (4.0 * d * d + m * m) * span;
      }
      // And what sampling leaves between the samples of a perfect fit (objective.h).
      floor += obj.interpolation_misfit(s.q);
      r.smoothness_expected_misfit = expected += floor;
      if (verbose) std::printf("discrepancy: noise and the fit test's floor give a data misfit of %.4e\n", expected);
    }
    r.smoothness_path.push_back({beta, misfit, s.prior_cost, s.iterations_done, s.converged()});
    if (verbose)
      std::printf("smoothness weight %.0e: data misfit %.4e (noise %.4e), prior %.4e, %s\n", beta, misfit, expected, s.prior_cost,
                  to_string(s.termination));
    if (s.q.allFinite()) q = s.q;
    chosen = s;
    r.smoothness_weight = beta;
    have = true;
    if (misfit <= expected) {
      r.smoothness_met = true;
      break;
    }
  }
  if (!have) throw std::logic_error("discrepancy_path: no weight tried");
  return chosen;
}

// More parameters than this: `auto` leaves the explicit Gauss–Newton matrix (P tangent solves per
// iteration) for products (docs/theory.md §7.7), and a sectional family starts from the
// coarse-to-fine ladder (§7.6).
constexpr int kExplicitGaussNewtonParameters = 16;

// The coarse-to-fine ladder (docs/theory.md §7.6): every sectional family tied into B = 1, 2, 4, …
// contiguous blocks, each level solved from the end of the previous one, until a level's fit is
// within noise and discretisation on the full model (finer levels would only refit what the data
// already hold) or B reaches the sections. Each level has its own automatic step (§5.2 for the
// level's P tied parameters: modes up to P + 2, never finer than the full run's; unless the scenario
// fixes the step or BDF chooses it): the coarse levels need only the low modes. Returns the start
// of the full parameterization's run.
struct Ladder {
  VectorXd q;
  int iterations = 0;
  std::string label;
  std::vector<RunResult::Attempt::Level> levels;
};
Ladder coarse_to_fine(const Problem& p, Objective& obj, const std::vector<std::string>& names,
                      const std::vector<std::vector<int>>& families, const VectorXd& start, const OptimizerOptions& oo,
                      ObjectiveCounters& extra, bool verbose) {
  std::size_t N = 0;
  for (const auto& f : families) N = std::max(N, f.size());
  Ladder out;
  out.q = start;
  out.label = "coarse-to-fine over";
  for (int B = 1; B < static_cast<int>(N); B *= 2) {
    auto [group, gnames] = block_grouping(names, families, B);
    TiedParameterization tied(*p.params, out.q, group, gnames);
    ObjectiveOptions lo = p.objective_options;
    // (BDF chooses its own steps: the level keeps the full run's options.)
    if (!(p.scenario.identification.time_step > 0) && lo.solver.step > 0 &&
        lo.solver.integrator != SolverOptions::Integrator::Bdf)
      lo.solver.step = std::max(lo.solver.step, identifier_step(p.scenario, p.model(), tied, p.signals));
    Objective level(p.model(), tied, p.signals, p.data, lo);
    OptimizerOptions ol = oo;
    ol.method = tied.size() <= kExplicitGaussNewtonParameters || !level.has_matrix_free_products() ? "gauss-newton"
                                                                                                    : "gauss-newton-krylov";
    ol.smoothness_weight = 0.0;  // the tied levels are smooth by construction
    ol.smoothness_chains.clear();
    ol.continuation = p.scenario.identification.continuation_misfit > 0;
    const OptimizerSummary sl = minimize(level, tied.initial(), ol, [&](const IterationRecord&) { io::check_interrupt(); });
    extra.Accumulate(level.counters());
    out.iterations += sl.iterations_done;
    if (sl.q.allFinite()) out.q = tied.expand(sl.q);
    out.label += " " + std::to_string(B);
    const bool explained = sl.q.allFinite() && test_fit(p, obj, out.q).within_noise_and_discretisation;
    out.levels.push_back({B, lo.solver.step, sl.cost, sl.iterations_done, to_string(sl.termination), explained});
    if (verbose)
      std::printf("  %d block%s per family (step %.3g s): %s%s\n", B, B > 1 ? "s" : "", lo.solver.step,
                  sl.BriefReport().c_str(), explained ? "; the fit is within noise and discretisation" : "");
    if (explained) break;
  }
  out.label += " blocks, then " + std::to_string(N) + " sections";
  return out;
}
}  // namespace

namespace {
void flag_mirror_ambiguity(const Problem& p, Objective& obj, RunResult& r, const MatrixXd& Y);
}  // namespace

bool better_attempt(const RunResult::Attempt& a, const RunResult::Attempt& b) {
  const int ra = (a.optimizer_converged && a.explains_data ? 2 : 0) + (a.explains_data ? 1 : 0);
  const int rb = (b.optimizer_converged && b.explains_data ? 2 : 0) + (b.explains_data ? 1 : 0);
  return ra != rb ? ra > rb : a.cost < b.cost;
}

RunResult run_identification(Problem& p, const RunOptions& ro) {
  if (p.scenario.identification.model == "nonlinear") return run_nonlinear_identification(p, ro);
  const auto t0 = std::chrono::steady_clock::now();
  RunResult r;
  r.scenario = p.scenario.name;
  r.names = p.params->names();
  r.initial = p.params->initial();
  r.truth = p.true_values;
  std::string method = ro.method.empty() ? p.scenario.identification.method : ro.method;
  const double smoothness = p.scenario.identification.smoothness;
  Objective obj(p.model(), *p.params, p.signals, p.data, p.objective_options);
  // auto (docs/theory.md §7.7): the explicit Gauss–Newton matrix up to its parameter limit; beyond
  // it matrix-free products with a prior (displacement sensors only: with rate sensors the explicit
  // matrix), else L-BFGS.
  if (method == "auto")
    method = p.params->size() <= kExplicitGaussNewtonParameters ? "gauss-newton"
             : smoothness != 0.0 ? (obj.has_matrix_free_products() ? "gauss-newton-krylov" : "gauss-newton")
                                 : "lbfgs";
  r.method = method;
  std::vector<std::vector<int>> chains;
  if (smoothness != 0.0) {
    if (method != "gauss-newton-krylov" && method != "gauss-newton")
      io::fail_field(p.scenario.source, "identification.smoothness", "needs method gauss-newton or gauss-newton-krylov (or auto)",
                     method);
    chains = section_families(r.names);
    if (chains.empty())
      io::fail_field(p.scenario.source, "identification.smoothness",
                     "needs sectional parameters (X_1 ... X_N) among those estimated", "none");
  }

  OptimizerOptions oo;
  oo.method = method;
  oo.max_iterations = ro.max_iterations.value_or(p.scenario.identification.max_iterations);
  oo.gradient_tolerance = p.scenario.identification.gradient_tolerance;
  oo.step_tolerance = p.scenario.identification.step_tolerance;
  oo.steepest_weights = p.scenario.identification.steepest_weights;
  oo.continuation = p.scenario.identification.continuation_misfit > 0;
  if (oo.continuation) oo.continuation_misfit = p.scenario.identification.continuation_misfit;
  if (!oo.steepest_weights.empty() && static_cast<int>(oo.steepest_weights.size()) != p.params->size())
    io::fail_field(p.scenario.source, "identification.steepest_weights",
                   "must hold one weight per estimated parameter (" + std::to_string(p.params->size()) + ")",
                   std::to_string(oo.steepest_weights.size()) + " values");
  Table table(*p.params, p.params->names().size() <= 3 && p.params->paper_form());
  auto progress = [&](const IterationRecord& rec) {
    io::check_interrupt();
    if (ro.verbose) table.row(rec);
  };
  oo.smoothness_chains = chains;
  // identification.start: auto starts a sectional family of more sections than the explicit
  // Gauss–Newton limit from the coarse-to-fine ladder: from the uniform start, its plain run stalls
  // (docs/theory.md §7.6).
  const auto families = section_families(r.names);
  std::size_t sections = 0;
  for (const auto& f : families) sections = std::max(sections, f.size());
  const std::string& start_how = p.scenario.identification.start;
  if (start_how == "coarse-to-fine" && families.empty())
    io::fail_field(p.scenario.source, "identification.start", "needs sectional parameters (X_1 ... X_N) among those estimated",
                   start_how);
  const bool ladder_first = start_how == "coarse-to-fine" ||
                            (start_how == "auto" && sections > static_cast<std::size_t>(kExplicitGaussNewtonParameters));
  ObjectiveCounters extra;  // solves of the tied levels' objectives
  VectorXd start = r.initial;
  std::string first_label = "plain " + method;
  int first_iterations = 0;
  std::vector<RunResult::Attempt::Level> first_levels;
  if (ladder_first) {
    if (ro.verbose) std::printf("%zu sections: coarse to fine from the start\n", sections);
    const Ladder lad = coarse_to_fine(p, obj, r.names, families, r.initial, oo, extra, ro.verbose);
    start = lad.q;
    first_label = lad.label;
    first_iterations = lad.iterations;
    first_levels = lad.levels;
  }
  if (ro.verbose) table.header();
  if (smoothness >= 0.0) {
    oo.smoothness_weight = smoothness;
    r.summary = minimize(obj, start, oo, progress);
    r.smoothness_weight = smoothness;
  } else {
    r.summary = discrepancy_path(p, obj, r, start, oo, progress, ro.verbose);
    oo.smoothness_weight = r.smoothness_weight;  // restarts keep the chosen prior
  }
  r.fit = test_fit(p, obj, r.summary.q);
  auto attempt_record = [&](const std::string& strategy, const std::string& how, const OptimizerSummary& s,
                            const FitTest& f, int iterations) {
    RunResult::Attempt a;
    a.strategy = strategy;
    a.method = how;
    a.termination = to_string(s.termination);
    a.optimizer_converged = s.converged();
    obj.set_horizon(obj.data_end());  // the cost over the whole record, whatever horizon the run ended on
    a.cost = INFINITY;
    try {
      if (s.q.allFinite()) a.cost = obj.cost(s.q);
    } catch (const io::Interrupted&) {
      throw;
    } catch (const std::exception&) {
    }
    if (!std::isfinite(a.cost)) a.cost = INFINITY;
    a.iterations = iterations;
    a.explains_data = f.explains_data;
    a.fit_message = f.message;
    return a;
  };
  r.attempts.push_back(attempt_record(first_label, method, r.summary, r.fit, first_iterations + r.summary.iterations_done));
  r.attempts.back().levels = first_levels;

  // Further attempts when the model at the estimate does not explain the data.
  // The second of the two starts of a sectional family: coarse to fine after a plain run, the plain
  // run after the ladder (a coarse level can land in a basin the full profile does not leave:
  // beam-ei8 started coarse to fine stops at J = 0.099 where the plain run reaches 4e-8).
  std::vector<std::string> strategies;
  if (!families.empty()) strategies.push_back(ladder_first ? "plain" : "coarse-to-fine");
  strategies.push_back("cautious-continuation");
  for (std::size_t k = 0; k < strategies.size() && static_cast<int>(k) < p.scenario.identification.restarts; ++k) {
    const std::string& how = strategies[k];
    // Restarts answer a false convergence: the optimiser stopped on a convergence test where the
    // model does not explain the data. The other start of a sectional family (coarse to fine, or
    // plain after the ladder) is tried whenever the residual exceeds noise and discretisation (a
    // local minimum of a sectional profile may still fit within a declared model error), and also
    // after a run that used up its iterations (sections the sensors barely see wander through any
    // budget: EI on 64 sections, docs/theory.md §7.8); the cautious continuation only when a
    // converged fit does not explain the data.
    const bool other_start = how == "coarse-to-fine" || how == "plain";
    const bool out_of_iterations = r.summary.termination == OptimizerSummary::Termination::MaxIterations;
    if (!r.summary.converged() && !(other_start && out_of_iterations)) break;
    if (other_start ? r.fit.within_noise_and_discretisation : r.fit.explains_data) continue;
    if (ro.verbose)
      std::printf("fit test: %s\nrestart %zu (%s) from the starting point\n",
                  r.fit.explains_data ? "the residual exceeds noise and discretisation" : r.fit.message.c_str(), k + 1,
                  how.c_str());
    OptimizerSummary s;
    int iterations = 0;
    std::string label;
    std::vector<RunResult::Attempt::Level> levels;
    if (how == "coarse-to-fine") {
      const Ladder lad = coarse_to_fine(p, obj, r.names, families, r.initial, oo, extra, ro.verbose);
      iterations += lad.iterations;
      label = lad.label;
      levels = lad.levels;
      if (ro.verbose) table.header();
      s = minimize(obj, lad.q, oo, progress);
    } else if (how == "plain") {
      label = "plain " + method;
      if (ro.verbose) table.header();
      s = minimize(obj, r.initial, oo, progress);
    } else {
      OptimizerOptions oc = oo;  // the run's own method, with a four times more cautious continuation
      oc.continuation = true;
      oc.continuation_misfit = (p.scenario.identification.continuation_misfit > 0 ? p.scenario.identification.continuation_misfit
                                                                                  : OptimizerOptions{}.continuation_misfit) / 4.0;
      label = oc.method + ", horizon continuation at misfit " + io::format_value(oc.continuation_misfit);
      if (ro.verbose) table.header();
      s = minimize(obj, r.initial, oc, progress);
    }
    iterations += s.iterations_done;
    const FitTest f = test_fit(p, obj, s.q);
    r.attempts.push_back(attempt_record(label, method, s, f, iterations));
    r.attempts.back().levels = levels;
    if (better_attempt(r.attempts.back(), r.attempts[static_cast<std::size_t>(r.chosen_attempt)])) {
      r.chosen_attempt = static_cast<int>(r.attempts.size()) - 1;
      r.summary = s;
      r.fit = f;
    }
    if (r.converged()) break;
  }
  r.summary.cost = r.attempts[static_cast<std::size_t>(r.chosen_attempt)].cost;  // over the whole record
  if (ro.verbose) std::printf("fit test: %s\n", r.fit.message.c_str());
  r.estimate = r.summary.q;
  if (ro.compute_std) {
    const auto ti = std::chrono::steady_clock::now();
    // Each sensor's stated noise level: the scenario's, else truth.json's (make_problem).
    std::vector<io::SensorSpec> sensors = p.scenario.sensors;
    for (std::size_t j = 0; j < sensors.size() && j < p.noise_std.size(); ++j) sensors[j].noise_std = p.noise_std[j];
    // The model's outputs and their sensitivities at q̂, kept for the mirror test and the interval.
    const MatrixXd Y = obj.predict(r.estimate);
    const MatrixXd G = obj.output_sensitivities(r.estimate);
    r.ident = identifiability_from(fisher_information(obj.data(), Y, G, sensors), r.estimate);
    flag_mirror_ambiguity(p, obj, r, Y);
    if (r.ident.noise_source == "scenario") {
      std::string origin;
      for (const auto& o : p.noise_origin) origin = origin.empty() || origin == o ? o : "scenario and truth.json";
      r.ident.noise_source = origin;
    }
    // The half-record refit (interval.h): the same fit on the first half of the record, from q̂.
    IntervalInputs ii;
    ii.estimate = r.estimate;
    // (A record too short to halve into two samples gets none: the interval is then not assessed.)
    if (const Measurements half_data = first_half(p.data); half_data.t.size() >= 2) {
      Objective half(p.model(), *p.params, p.signals, half_data, p.objective_options);
      OptimizerOptions oh = oo;
      oh.continuation = false;
      const OptimizerSummary s = minimize(half, r.estimate, oh, [&](const IterationRecord&) { io::check_interrupt(); });
      r.half_record_estimate = ii.half_record_estimate = s.q;
      r.half_record_converged = ii.half_record_converged = s.converged();
    }
    // The smoothing shift (interval.h): the refit at a tenth of the prior's weight, from q̂.
    if (oo.smoothness_weight > 0.0) {
      OptimizerOptions os = oo;
      os.smoothness_weight = oo.smoothness_weight / 10.0;
      os.continuation = false;
      const OptimizerSummary s = minimize(obj, r.estimate, os, [&](const IterationRecord&) { io::check_interrupt(); });
      ii.smoothing_estimate = s.q;
      ii.smoothing_converged = s.converged();
    }
    ii.consider = consider_terms(p, r.ident, r.estimate, Y, G, r.fit.discretisation);
    r.interval = uncertainty_interval(r.ident, ii);
    flag_wide_intervals(r);
    r.identifiability_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - ti).count();
  }
  r.counters = obj.counters();
  r.counters.Accumulate(extra);
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

nlohmann::json RunResult::to_json(const Problem& p) const {
  using nlohmann::json;
  json params = json::array();
  for (std::size_t i = 0; i < names.size(); ++i) {
    json e{{"name", names[i]}, {"initial", initial[static_cast<Eigen::Index>(i)]},
           {"estimate", estimate[static_cast<Eigen::Index>(i)]}};
    const auto it = truth.find(names[i]);
    if (it != truth.end()) {
      e["truth"] = it->second;
      e["relative_error"] = estimate[static_cast<Eigen::Index>(i)] / it->second - 1.0;
    }
    if (ident.std.size() > static_cast<Eigen::Index>(i)) {
      // A flagged parameter has no standard deviation worth the name: null, with the reason.
      const bool ok = ident.identifiable[i];
      const double sd = ident.std[static_cast<Eigen::Index>(i)], res = ident.resolution[static_cast<Eigen::Index>(i)];
      e["std"] = ok && std::isfinite(sd) ? json(sd) : json(nullptr);
      e["resolution"] = ok && std::isfinite(res) ? json(res) : json(nullptr);
      e["identifiable"] = ok;
      if (!ok && i < ident.reason.size()) e["not_identifiable_because"] = ident.reason[i];
      // The interval (interval.h): ±half_width about the estimate, and what it is made of.
      const auto ie = static_cast<Eigen::Index>(i);
      const double hw = interval.half_width.size() > ie ? interval.half_width[ie] : std::nan("");
      if (ok && std::isfinite(hw)) {
        json comp{{"noise_2std", interval.noise[ie]},
                  {"residual_2resolution", interval.residual[ie]},
                  {"half_record_shift", interval.half_record_shift[ie]},
                  {"smoothing_shift", interval.smoothing_shift[ie]},
                  {"consider", interval.consider[ie]}};
        e["interval"] = {{"half_width", hw}, {"low", estimate[ie] - hw}, {"high", estimate[ie] + hw},
                         {"relative_half_width", hw / std::abs(estimate[ie])}, {"components", comp}};
        if (it != truth.end()) e["interval"]["covers_truth"] = std::abs(estimate[ie] - it->second) <= hw;
      } else {
        e["interval"] = nullptr;
      }
      if (half_record_estimate.size() > ie) e["half_record_estimate"] = half_record_estimate[ie];
    } else {
      // --no-std: not assessed, which is not the same as identifiable.
      e["std"] = nullptr;
      e["resolution"] = nullptr;
      e["identifiable"] = nullptr;
      e["interval"] = nullptr;
    }
    params.push_back(e);
  }
  json iters = json::array();
  for (const auto& it : summary.iterations) {
    json values = json::object();
    for (std::size_t i = 0; i < names.size(); ++i) values[names[i]] = it.q[static_cast<Eigen::Index>(i)];
    iters.push_back({{"k", it.k}, {"cost", it.cost}, {"values", values}, {"physical", p.params->physical(it.q)},
                     {"gradient_norm", it.gradient_norm}, {"horizon", it.horizon}});
  }
  json out{{"scenario", scenario},
           {"model", model},
           {"method", method},
           {"parameters", params},
           {"physical_estimate", p.params->physical(estimate)},
           {"iterations", iters},
           {"termination", to_string(summary.termination)},
           {"termination_message", summary.message},
           {"converged", converged()},
           {"optimizer_converged", summary.converged()},
           {"fit_test", [&] {
              nlohmann::json sens = nlohmann::json::array();
              for (const auto& sf : fit.sensors)
                sens.push_back({{"name", sf.name}, {"rms_signal", sf.rms_signal}, {"rms_residual", sf.rms_residual},
                                {"noise", sf.noise}, {"noise_estimated", sf.noise_estimated}, {"systematic", sf.systematic},
                                {"discretisation", std::isfinite(sf.discretisation) ? nlohmann::json(sf.discretisation) : nlohmann::json(nullptr)},
                                {"allowed", sf.allowed}, {"explained", sf.explained}});
              return nlohmann::json{{"explains_data", fit.explains_data},
                                    {"within_noise_and_discretisation", fit.within_noise_and_discretisation},
                                    {"model_error", fit.model_error}, {"ratio", fit.ratio},
                                    {"message", fit.message}, {"sensors", sens}};
            }()},
           {"attempts", [&] {
              nlohmann::json a = nlohmann::json::array();
              for (std::size_t k = 0; k < attempts.size(); ++k) {
                a.push_back({{"strategy", attempts[k].strategy}, {"method", attempts[k].method},
                             {"termination", attempts[k].termination}, {"optimizer_converged", attempts[k].optimizer_converged},
                             {"cost", std::isfinite(attempts[k].cost) ? nlohmann::json(attempts[k].cost) : nlohmann::json(nullptr)},
                             {"iterations", attempts[k].iterations}, {"explains_data", attempts[k].explains_data},
                             {"fit_message", attempts[k].fit_message}, {"chosen", static_cast<int>(k) == chosen_attempt}});
                for (const auto& l : attempts[k].levels)
                  a.back()["levels"].push_back({{"blocks", l.blocks}, {"step", l.step},
                                                {"cost", std::isfinite(l.cost) ? nlohmann::json(l.cost) : nlohmann::json(nullptr)},
                                                {"iterations", l.iterations}, {"termination", l.termination},
                                                {"explained", l.explained}});
              }
              return a;
            }()},
           {"cost", summary.cost},
           {"smoothness", [&] {
              nlohmann::json sm{{"weight", smoothness_weight}, {"prior_cost", summary.prior_cost}};
              if (!smoothness_path.empty()) {
                sm["rule"] = "discrepancy";
                sm["expected_misfit"] = smoothness_expected_misfit;  // noise and the fit test's floor
                sm["discrepancy_met"] = smoothness_met;
                nlohmann::json path = nlohmann::json::array();
                for (const auto& e : smoothness_path)
                  path.push_back({{"weight", e.weight}, {"data_misfit", e.data_misfit}, {"prior_cost", e.prior_cost},
                                  {"iterations", e.iterations}, {"converged", e.converged}});
                sm["path"] = path;
              }
              return sm;
            }()},
           {"krylov_iterations", summary.krylov_iterations},
           // Every attempt's iterations with its coarse-to-fine levels (`iterations` is the chosen
           // run's history alone).
           {"iterations_all_attempts", iterations_all_attempts()},
           {"gradient_evaluations", counters.gradient_evaluations},
           {"forward_solves", counters.forward_solves},
           {"costate_solves", counters.costate_solves},
           {"sensitivity_solves", counters.sensitivity_solves},
           {"checkpointed_passes", counters.checkpointed_passes},
           {"checkpoint_resolves", counters.checkpoint_resolves},
           {"wall_seconds", wall_seconds},
           {"timing_seconds",
            {{"forward", counters.forward_seconds},
             {"costate", counters.costate_seconds},
             {"sensitivity", counters.sensitivity_seconds},
             {"quadrature", counters.quadrature_seconds},
             {"optimizer_total", summary.wall_seconds},
             {"identifiability", identifiability_seconds}}},
           {"integrator",
            {{"name", model == "nonlinear" ? std::string("esdirk-newton (nonlinear model)")
                                            : std::string(integrator_name(p.objective_options.solver.integrator))},
             {"step", model == "nonlinear" ? integrator_step : p.objective_options.solver.step},
             {"rtol", model == "nonlinear" ? json(nullptr) : json(p.objective_options.solver.rtol)},
             {"steps", counters.solver.steps},
             {"step_rule", p.scenario.identification.time_step > 0 ? std::string("given") : p.scenario.identification.step_rule},
             {"resolved_modes", p.content.mode},
             {"modes_below_nyquist", p.content.modes_below_nyquist},
             {"visible_content_modes", p.content.content_mode}}},
           {"data_source", p.data_source},
           {"elements", p.structure->elements()},
           {"settings", io::to_json(p.scenario)}};
  if (ident.std.size() > 0) {
    out["identifiability"] = {{"assessed", true},
                              {"condition_number", safe(ident.condition_number)},
                              {"noise_std", ident.noise_std},
                              {"noise_source", ident.noise_source},
                              {"chi2", ident.chi2},
                              {"data_values", ident.data_values},
                              {"mirror_chi2_difference", std::isfinite(ident.mirror_chi2_difference) ? json(ident.mirror_chi2_difference) : json(nullptr)},
                              {"half_record_refit_converged",
                               half_record_estimate.size() != 0 ? json(half_record_converged) : json(nullptr)},
                              {"consider", [&] {
                                 json c = json::array();
                                 for (const auto& t : interval.terms) {
                                   json sh = json::object();
                                   for (std::size_t i = 0; i < names.size() && static_cast<Eigen::Index>(i) < t.shift.size(); ++i)
                                     sh[names[i]] = t.shift[static_cast<Eigen::Index>(i)];
                                   c.push_back({{"field", t.field}, {"value", t.value}, {"tolerance", t.delta}, {"shift", sh}});
                                 }
                                 return c;
                               }()},
                              {"interval_note", interval.note}};
  } else {
    out["identifiability"] = {{"assessed", false}, {"why", "run with --no-std: no standard deviations, no identifiability flags"}};
  }
  if (p.data_source != "" && p.data_source.rfind("synthetic", 0) != 0)
    out["data_columns"] = {{"sensors", p.columns.sensors},
                           {"inputs_from_data", p.columns.inputs_from_data},
                           {"inputs_from_scenario", p.columns.inputs_from_scenario},
                           {"unused", p.columns.unused},
                           {"stepped_inputs", [&] {
                              nlohmann::json a = nlohmann::json::array();
                              for (const auto& st : p.columns.stepped_inputs)
                                a.push_back({{"name", st.name}, {"largest_jump", st.jump}, {"at", st.at},
                                             {"switch_shift_up_to", 0.5 * st.sample},
                                             {"scenario_gives_signal", st.scenario_signal}});
                              return a;
                            }()}};
  return out;
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

void write_outputs(io::RunDirectory& dir, Problem& p, const RunResult& r) {
  // fit.csv: measured, predicted and residual per sensor at the sample times.
  MatrixXd predicted = r.predicted;
  if (predicted.size() == 0) {
    Objective obj(p.model(), *p.params, p.signals, p.data, p.objective_options);
    predicted = obj.predict(r.estimate);
  }
  const io::DataTable tab = fit_table(p.data, predicted);
  io::write_csv(dir.path("fit.csv"), tab);
  // fit.gp, rendered to fit.png when gnuplot is installed (the script stays for other terminals).
  std::vector<std::pair<int, double>> cost;
  for (const auto& it : r.summary.iterations) cost.emplace_back(it.k, it.cost);
  io::write_text_atomic(dir.path("fit.gp"), fit_plot_script(p.data.names, cost));
  switch (render_gnuplot(dir.staging(), "fit.gp")) {
    case RenderStatus::Rendered: break;
    case RenderStatus::NoGnuplot: std::fprintf(stderr, "scole-identify: note: gnuplot is not installed; no fit.png\n"); break;
    case RenderStatus::Failed: std::fprintf(stderr, "scole-identify: note: gnuplot could not render fit.png\n"); break;
  }
  io::write_json_atomic(dir.path("identify.json"), r.to_json(p));
}

Measurements first_half(const Measurements& data) {
  Measurements first = data;
  const double t_half = first.t.front() + 0.5 * (first.t.back() - first.t.front());
  std::size_t n = 0;
  while (n < first.t.size() && first.t[n] <= t_half) ++n;
  first.t.resize(n);
  first.z.conservativeResize(static_cast<Eigen::Index>(n), Eigen::NoChange);
  return first;
}

namespace {
// The mirror test (docs/theory.md §8.1): the Fisher matrix sees only the estimate's neighbourhood,
// so a second profile that explains the data as well is invisible to it. A beam's sections have one
// such candidate by construction — the profile reversed end for end, which a symmetric support,
// load and sensor layout cannot tell from the original. Each family of sections X_1 … X_N is
// reversed (the other parameters kept) and the model's χ² there compared with the estimate's,
// with the same noise levels as the Fisher step: if the difference is below 4 (the
// likelihood-ratio bound of one degree of freedom at 95 %, rounded) the data cannot tell the two
// profiles apart, and every section whose mirrored value lies more than 2 std from its estimate is
// flagged. One state solve; none when the estimate is its own mirror within 2 std.
void flag_mirror_ambiguity(const Problem& p, Objective& obj, RunResult& r, const MatrixXd& Y) {
  const auto families = section_families(r.names);
  if (families.empty() || r.ident.identifiable.empty()) return;
  VectorXd qm = r.estimate;
  for (const auto& f : families)
    for (std::size_t j = 0; j < f.size(); ++j) qm[f[j]] = r.estimate[f[f.size() - 1 - j]];
  std::vector<int> differ;
  for (const auto& f : families)
    for (int i : f) {
      const auto u = static_cast<std::size_t>(i);
      if (!r.ident.identifiable[u]) continue;
      if (std::abs(qm[i] - r.estimate[i]) > 2.0 * r.ident.std[i]) differ.push_back(i);
    }
  if (differ.empty()) return;
  MatrixXd Ym;
  try {
    Ym = obj.predict(qm);
  } catch (const io::Interrupted&) {
    throw;
  } catch (const std::exception&) {
    return;  // the mirrored profile cannot be solved: no second candidate
  }
  double c0 = 0.0, c1 = 0.0;
  for (Eigen::Index i = 0; i < Y.rows(); ++i)
    for (Eigen::Index k = 0; k < Y.cols(); ++k) {
      const double sd = static_cast<std::size_t>(k) < r.ident.noise_std.size() ? r.ident.noise_std[static_cast<std::size_t>(k)] : 0.0;
      if (!(sd > 0.0)) continue;
      const double w = 1.0 / (sd * sd);
      c0 += w * std::pow(Y(i, k) - p.data.z(i, k), 2);
      c1 += w * std::pow(Ym(i, k) - p.data.z(i, k), 2);
    }
  r.ident.mirror_chi2_difference = c1 - c0;
  if (!(c1 - c0 < 4.0)) return;
  for (int i : differ) {
    const auto u = static_cast<std::size_t>(i);
    r.ident.identifiable[u] = false;
    char buf[260];
    if (c1 - c0 > -4.0)
      std::snprintf(buf, sizeof buf,
                    "the profile reversed end for end (this section %.6g instead of %.6g) fits the data as well (chi-square "
                    "difference %.3g, below 4): the data cannot tell the two apart",
                    qm[i], r.estimate[i], c1 - c0);
    else  // the mirror is the better fit: the estimate is not the best one
      std::snprintf(buf, sizeof buf,
                    "the profile reversed end for end (this section %.6g instead of %.6g) fits the data better (chi-square "
                    "lower by %.3g): the estimate is not the best fit",
                    qm[i], r.estimate[i], c0 - c1);
    r.ident.reason[u] = buf;
  }
}
}  // namespace

void flag_wide_intervals(RunResult& r) {
  for (std::size_t i = 0; i < r.names.size() && i < r.interval.too_wide.size(); ++i)
    if (r.ident.identifiable[i] && r.interval.too_wide[i]) {
      r.ident.identifiable[i] = false;
      char buf[160];
      std::snprintf(buf, sizeof buf, "uncertainty interval ±%.3g is %.3g of the estimate: above 0.5",
                    r.interval.half_width[static_cast<Eigen::Index>(i)],
                    r.interval.half_width[static_cast<Eigen::Index>(i)] / std::abs(r.estimate[static_cast<Eigen::Index>(i)]));
      r.ident.reason[i] = buf;
    }
}

}  // namespace scoleid::identify
