#pragma once
// Two-stage Gauss–Legendre collocation (fourth order, A-stable, symplectic) for the multibody
// equations of an unconstrained Simbody system, with a simplified Newton iteration on the
// linearisation's Jacobian (docs/theory.md §9.5). Selected by name (truth.integrator:
// gauss-legendre), for records from rest under smooth loads.
//
// Equations: q' = N(q) u, u' = a(t, q, u). One step t0 -> t1 = t0 + h has two stages at
// t0 + c_i h, c = 1/2 -+ sqrt(3)/6, with increments Z_i = Y_i - y0 solving
//     Z_i = h sum_j a_ij f(t0 + c_j h, y0 + Z_j),   a = [[1/4, 1/4 - sqrt3/6], [1/4 + sqrt3/6, 1/4]],
// and y1 = y0 + sum_i d_i Z_i with d = b^T a^-1 = (-sqrt3, sqrt3) (the collocation polynomial at
// t1: no evaluation at the converged stages is needed).
// Why this method: like the trapezoidal rule (trapezoidal.h) it is A-stable and its amplification
// on an undamped linear mode is unitary (the (2,2) Padé approximant of exp(i omega h)), so the
// chain's lightly damped top modes neither grow nor get damped away; and it conserves every
// quadratic invariant exactly (energy of the linear undamped system, quaternion norms). Its
// phase error is (omega h)^5 / 720 per step instead of (omega h)^3 / 12: at the same accuracy on
// the fundamental mode its step is ~25x longer, and the step is then bounded by the samples.
// The price: the chain's top modes sit at omega h >> 1. Where they carry energy (a chain started
// deformed, or struck) their nonlinear coupling is not resolved at the default accuracy, and the
// Newton matrix's condition, ~(omega_max h)^2, lifts the residual's round-off.
//
// Newton: with A = da/d(delta) (q = q + N delta), B = da/du, dq'/dq neglected and N frozen per
// stage, eliminating the stage position corrections delta_i = -g_i + h sum_j a_ij du_j
// (g_i = N^-1 G_q,i) leaves one 2 nu x 2 nu system for both stages' velocity corrections,
//     (I - h a (x) B - h^2 a^2 (x) A) du = -G_u - h (a (x) A) g,
// factorised once per (Jacobian, h). The positions are then corrected in q itself,
// dq_i = -G_q,i + h sum_j a_ij N(Q_j) du_j, so the whole residual G_q is driven to zero: for a
// quaternion (nq > nu) N^-1 drops G_q's radial part, and y1 = y0 + sqrt3 (Z_2 - Z_1) turns what a
// stage keeps of it into an attitude error first order in h. The stages start from the previous
// step's collocation polynomial extrapolated (from Euler increments at the first step and after an input
// breakpoint). The iteration stops when eta ||dZ|| <= tol, eta = theta / (1 - theta) the
// estimated error factor left by a correction, theta the contraction of this step's successive
// corrections (Hairer & Wanner, Solving ODEs II, IV.8): at least two corrections per step, unless
// the first is below 1e-3 tol. (Judging a first correction by an earlier step's theta, as
// Hairer & Wanner do, fails here: a theta measured on corrections at round-off is ~0 and lets
// later steps stop one correction short; the undamped cantilever's energy then drifts 100x.)
// A slowly contracting iteration refreshes the Jacobian at y0 (twice per step at most), then goes
// on while it contracts; corrections that stop shrinking within 100 tol are the residual's
// round-off and end the step (counted in the summary). A step whose iteration still fails is
// taken as two halves (down to 1/64 of it, counted), and only then does the run fail.
//
// Step: h_max = (720 accuracy)^(1/5) / omega_1, the step whose phase error on omega_1 is
// `accuracy` per step (omega_1: the caller's reference, truth_run.h; the fundamental flexible mode,
// or a higher mode the inputs excite, weighed by its share of the record); steps land on every requested time, so
// h <= h_max is the interval over the smallest integer that satisfies it. The stages lie inside
// the step, so an input that jumps at t1 is never evaluated there; y1 is realized at t1 (the
// input's right limit).
#include <map>
#include <string>

#include <Eigen/Dense>
#include <Simbody.h>

#include "scoleid/model/implicit_step.h"

namespace scoleid::model {

struct GaussLegendreOptions : ImplicitStepOptions {
  // How far each step's end is realized (Velocity or Acceleration): the method itself needs only
  // its stages' accelerations, so a caller that reads positions and velocities saves the step
  // end's dynamics.
  SimTK::Stage output_stage = SimTK::Stage::Acceleration;
  bool IsValid(std::string* why) const;
};

struct GaussLegendreSummary {
  int steps = 0;
  int realizations = 0;
  int newton_iterations = 0;       // corrections computed
  int jacobians = 0;
  int factorizations = 0;
  double max_step = 0.0;           // the step bound in use
  double largest_step = 0.0;       // the largest step taken
  double lowest_omega = 0.0;       // rad/s, omega_1 (0: none)
  // Steps whose Newton corrections stopped shrinking above the tolerance but within 100 times it
  // (the residual's round-off, at steps long against the chain's top modes), and the largest
  // such correction (relative to the state scale).
  int roundoff_limited_steps = 0;
  int split_steps = 0;             // steps whose Newton iteration failed, taken as two halves
  double largest_roundoff_correction = 0.0;
  // Relative frequency error of the method at omega_1 with the largest step, (omega h)^4/720.
  double lowest_mode_frequency_error() const {
    const double x = lowest_omega * largest_step;
    return x * x * x * x / 720.0;
  }
};

class GaussLegendreIntegrator {
 public:
  // `initial` need not be realized. Throws std::invalid_argument for a system with constraints.
  GaussLegendreIntegrator(const SimTK::MultibodySystem& system, const SimTK::State& initial,
                          const GaussLegendreOptions& options = {});

  // Advances to t_end in equal steps of at most max_step. breakpoint: the inputs jump at t_end,
  // so the next step does not extrapolate this one's stages across it.
  void advance_to(double t_end, bool breakpoint = false);

  // The current state, realized to options.output_stage (the initial state: to Acceleration).
  const SimTK::State& state() const { return state_; }
  double time() const { return state_.getTime(); }
  double max_step() const { return summary_.max_step; }
  const GaussLegendreSummary& summary() const { return summary_; }

 private:
  void refresh_jacobian(const SimTK::State& at);
  const Eigen::PartialPivLU<Eigen::MatrixXd>& newton_matrix(double h);
  void predict(double h);
  // One step; false (and the state unchanged, the reason in *why) if its Newton iteration fails.
  bool step(double h, std::string* why);
  void step_or_split(double h, int depth);
  void realize(SimTK::State& s) const;

  const SimTK::MultibodySystem& system_;
  const SimTK::SimbodyMatterSubsystem& matter_;
  GaussLegendreOptions options_;
  GaussLegendreSummary summary_;
  SimTK::State state_;       // accepted, realized to Acceleration
  SimTK::State stage_[2];    // the stages' iterates
  Eigen::MatrixXd A_, B_;    // da/d(delta), da/du
  std::map<long long, Eigen::PartialPivLU<Eigen::MatrixXd>> factors_;  // by h in ps
  // The last step's stage increments (q then u, per stage) and its length, for the predictor;
  // h_prev_ = 0: none (first step, or the last one ended at an input breakpoint).
  Eigen::VectorXd zq_[2], zu_[2];
  double h_prev_ = 0.0;
  double u_scale_ = 0.0;     // running max |u|, for the Newton tolerance
  double d_scale_ = 0.0;     // running max |q - q_initial| (same role for positions)
  SimTK::Vector q_initial_;
};

}  // namespace scoleid::model
