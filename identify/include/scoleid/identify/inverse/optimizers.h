#pragma once
// Minimisers of J(q) over positive parameters. All work on x = log q (positivity by
// construction, and steps measured relative to each parameter); gradients transform as
// ∂J/∂x_i = q_i ∂J/∂q_i.
//
//   steepest-descent  the paper's update q_i ← q_i − w_i ∂J/∂q_i. With weights given, exactly
//                     that, halving the step while the cost does not decrease (monotone); without
//                     weights, w_i = α q_i² (steepest descent in log q) with α from backtracking.
//   lbfgs             limited-memory BFGS (m = 8) on x with an Armijo backtracking line search;
//                     one costate gradient per trial point.
//   Every method takes the optional smoothness prior (OptimizerOptions::smoothness_weight): its
//   value and gradient in x are added to the data's (gradient methods), and its constant matrix
//   too (gauss-newton; gauss-newton-krylov adds its product).
//   gauss-newton      trust-region Gauss–Newton (Levenberg) on x from forward sensitivities;
//                     see gauss_newton_step.h for the step and the radius, and below for the
//                     horizon continuation. With more than 16 parameters a trial point on the
//                     whole record gets its cost alone and the matrix only once accepted.
//   gauss-newton-krylov  inexact trust-region Gauss–Newton: the step from truncated conjugate
//                     gradients (Steihaug) on matrix-free products H v (objective.h,
//                     gauss_newton_product: one tangent and one costate solve each), stopped by the
//                     Eisenstat–Walker forcing η = min(½, √(‖g‖/‖g₀‖)); the cost of a step follows
//                     the number of directions the data inform, not P. Displacement sensors
//                     only. docs/theory.md §7.7–7.8.
//
// Horizon continuation (every method, `continuation`; described for Gauss–Newton, the gradient
// methods do the same with a misfit-profile state solve after each accepted step while the
// horizon is short, and drop their L-BFGS curvature pairs when it grows). Far from the solution the model and the
// data drift out of phase: a frequency error δω gives a phase error δω·t that grows along the
// record, and over many cycles the cost is no longer well described by its Gauss–Newton model
// (its valleys repeat at every cycle slipped). The misfit of the data on [t0, T] against the model
// therefore bounds the phase error accumulated up to T. The optimiser fits the data on a horizon
// [t0, T] (t0 the misfit's response_start: after a quiet start, where the inputs begin to act)
// with T the longest time up to which the relative mean-square misfit per sensor
// (objective.h, MisfitProfile) stays below `continuation_misfit` (but at least
// `continuation_min_fraction` of the record), and after every accepted step lengthens T the same
// way from the state solve it has just done (the misfit profile comes with it). When the fit on a
// short horizon has converged (a termination test below fires) but the misfit beyond still exceeds
// the bound, T is doubled. The tests for termination apply on the whole record only. Every
// accepted step on any horizon is an iteration (the table shows its horizon and its cost there).
// On a short horizon the data resolve fewer directions than the whole record will (the weakly
// seen parameters are fixed mostly by its later part), so the Levenberg parameter is kept at
// λ >= short_horizon_floor·J there: with R normalising each sensor, μ/J ≈ 2/ρ² for a direction of
// curvature μ whose output effect equals the whole residual at a relative change ρ, so with the
// default 0.1 a direction the short record cannot pin down to better than a factor ~5 (ρ >~ 4.5)
// is held back until the horizon grows, instead of being thrown far by the residual of the
// well-seen ones. On the whole record λ has no floor (plain Gauss–Newton near the solution).
//
// Termination (stated in Summary::termination): relative parameter step below step_tolerance,
// scaled gradient ‖g_x‖∞ below gradient_tolerance·max(J, tiny), cost below cost_floor, relative
// cost decrease over an accepted step below cost_stall (only directions the data barely see are
// still moving: the identifiability report flags them) — for Gauss–Newton also before a trial,
// when the undamped step left predicts below 1e-3 of that (a move of ~0.03 std, docs/theory.md
// §7.4) — or the iteration limit. cost_stall = 0
// (default) is automatic: for gauss-newton 1/N, N the number of data values (samples × sensors)
// on the horizon — fitting one more free parameter to white noise of the residual's size lowers
// J by J/N on average, so a Gauss–Newton step that gains less is not distinguishable from
// fitting noise; for the gradient methods, whose steps can gain little while still far from the
// minimum, 1e-5.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "scoleid/identify/inverse/objective.h"
#include "scoleid/io/types.h"

namespace scoleid::identify {

struct OptimizerOptions {
  io::Method method = io::Method::GaussNewton;  // not Auto: resolved before (run/strategy.h)
  int max_iterations = 50;
  double gradient_tolerance = 1e-9;
  double step_tolerance = 1e-5;
  double cost_floor = 1e-28;
  double cost_stall = 0.0;    // relative decrease of J over an accepted step below which we stop; 0 = automatic
  std::vector<double> steepest_weights;  // w_i, paper form; empty = automatic
  // gauss-newton trust region, in the Euclidean norm of log q (1 = a factor e)
  double trust_radius = 1.0;      // first radius
  double max_trust_radius = 5.0;  // largest radius
  // gauss-newton extrapolation along an accepted step whose actual decrease exceeds the
  // predicted one by this ratio: 2δ, 4δ, … up to max_extrapolation·δ while the cost falls
  double extrapolation_ratio = 1.25;
  double max_extrapolation = 8.0;
  // gauss-newton horizon continuation (see above)
  bool continuation = true;
  double continuation_misfit = 0.05;        // bound on the relative mean-square misfit per sensor
  double continuation_min_fraction = 0.125;  // shortest horizon, as a fraction of the record
  double short_horizon_floor = 0.1;          // λ >= this · J on a horizon shorter than the record
  // gauss-newton-krylov: CG iterations per step (each one matrix-free product: two solves)
  int max_krylov_iterations = 50;
  // A run continuing from another's end point on the same objective (the discrepancy path's next
  // weight): that run's end_matrix, the data's matrix taken at the start instead of evaluating one
  // (empty or another size: evaluated). Should a step it shapes fail (rejected, or gaining less
  // than the stall threshold), the start's own matrix is evaluated and the step taken again.
  // Used by gauss-newton with many parameters only.
  MatrixXd start_matrix;
  // Smoothness prior on x = log q (every method; docs/theory.md §7.8):
  //   ½ β Σ_chains Σ_j (x_{c_{j+1}} − x_{c_j})²
  // over chains of neighbouring sections (e.g. the indices of EI_1 … EI_N). β = 0: off.
  double smoothness_weight = 0.0;
  std::vector<std::vector<int>> smoothness_chains;
  bool IsValid(std::string* why) const;
};

struct IterationRecord {
  int k = 0;
  double cost = 0.0;
  VectorXd q;
  double gradient_norm = 0.0;  // ‖∂J/∂log q‖∞; NaN where not evaluated (a run's last point whose gradient nothing needed)
  double horizon = 0.0;        // end of the data the cost was taken over
};

struct OptimizerSummary {
  // DataExplained: not an optimiser's stop but the run layer's (run/attempts.cpp): a coarse level of
  // the coarse-to-fine ladder already explains the data within noise and discretisation, so the
  // full parameterization is not run from there (docs/theory.md §7.6).
  enum class Termination {
    StepTolerance,
    GradientTolerance,
    CostFloor,
    CostStalled,
    MaxIterations,
    LineSearchFailed,
    DataExplained,
    // Not an optimiser's stop: a signal or the wall-time limit ended the run, and the run layer kept
    // the last iterate reached (run/identify_run.h, RunOptions::keep_interrupted).
    Interrupted
  };
  Termination termination = Termination::MaxIterations;
  std::string message;
  VectorXd q;
  double cost = 0.0;        // with the prior's share, if any
  double prior_cost = 0.0;  // the smoothness prior's share of cost
  long krylov_iterations = 0;  // gauss-newton-krylov: CG iterations (matrix-free products) in all
  // gauss-newton with many parameters: the data's Gauss–Newton matrix in log q that holds at q (q's
  // own, or that of the point before when the run ended on a step that gained less than the stall
  // threshold or moved less than the step tolerance); empty otherwise (a run that failed, a short
  // horizon). For OptimizerOptions::start_matrix of a run from q (docs/theory.md §7.2).
  MatrixXd end_matrix;
  std::vector<IterationRecord> iterations;
  int iterations_done = 0;
  double wall_seconds = 0.0;
  bool converged() const {
    return termination == Termination::StepTolerance || termination == Termination::GradientTolerance ||
           termination == Termination::CostFloor || termination == Termination::CostStalled ||
           termination == Termination::DataExplained;
  }
  std::string BriefReport() const;
};

const char* to_string(OptimizerSummary::Termination t);

// What minimize's first point evaluates at q0 on the whole record (Gauss–Newton: the matrix, or
// with many parameters the gradient and step matrix; nothing for the other methods), so that the
// objective keeps it for a run from q0 that follows (its last evaluation is kept: objective.h).
// For a caller with a thread idle meanwhile; a point that cannot be evaluated is left to the run.
void evaluate_start(Misfit& objective, const VectorXd& q0, const OptimizerOptions& options);

// `on_iteration` is called after every accepted iterate (and for k = 0), for progress output.
OptimizerSummary minimize(Misfit& objective, const VectorXd& q0, const OptimizerOptions& options,
                          const std::function<void(const IterationRecord&)>& on_iteration = {});

}  // namespace scoleid::identify
