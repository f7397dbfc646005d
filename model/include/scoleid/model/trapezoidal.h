#pragma once
// Implicit trapezoidal rule for the multibody equations of an unconstrained Simbody system,
// with a simplified Newton iteration on the linearisation's Jacobian.
//
// Equations: q' = N(q) u, u' = a(t, q, u) (a from realize(Acceleration)). One step t0 -> t1 = t0 + h:
//     q1 = q0 + h/2 (N(q0) u0 + N(q1) u1)
//     u1 = u0 + h/2 (a0 + a(t1, q1, u1)).
// Why this method for the mast chains: their top modes (hundreds of Hz at n = 40) are lightly
// damped, so explicit steps are bounded by them and BDF3-5 are unstable on them. The trapezoidal
// rule is A-stable and, on the linear(ised) undamped system, conserves the energy exactly: mode
// omega is carried with its amplitude and a frequency (2/h) atan(omega h / 2), i.e. a relative
// frequency error of (omega h)^2 / 12 for omega h << 1. Modes with omega h >~ 1 are mapped to lower
// frequencies but keep their (small) energy; at h equal to the output interval they lie above
// the sampled data's Nyquist frequency anyway.
//
// Newton: residuals G_q = q - q0 - h/2 (q0' + q'), G_u = u - u0 - h/2 (a0 + a). With
// A = da/d(delta) (q = q + N delta), B = da/du and dq'/dq neglected, eliminating the position
// correction (delta_d = -N^-1 G_q + h/2 delta_u) leaves an nu x nu system
//     (I - h/2 B - h^2/4 A) delta_u = -G_u - h/2 A N^-1 G_q,
// factorised once per (Jacobian, h). The iteration starts at y0, whose residual needs no new
// evaluation; a step is accepted at the first iterate whose next correction is below the
// tolerance, so on a nearly linear system one or two evaluations of a per step suffice, and the
// accepted iterate's realized state is the step's state. A slowly contracting iteration refreshes
// the Jacobian at the current iterate.
//
// Step: h_max = (12 accuracy)^(1/3) / omega_1, the step whose local error on the structure's
// fundamental flexible mode omega_1 is `accuracy` of its amplitude per step (omega_1 given by the
// caller, who can linearise the structure without its inputs, or else the lowest oscillatory mode
// of the linearisation about the system's default state, inputs at t = 0 included);
// steps land on every requested time (samples, input breakpoints), so h <= h_max is the sample
// interval over the smallest integer that satisfies it. The end of a step that finishes at an
// input breakpoint is evaluated just before it (the input's left limit), the next step starts
// from its right limit.
#include <map>
#include <string>

#include <Eigen/Dense>
#include <Simbody.h>

#include "scoleid/model/implicit_step.h"

namespace scoleid::model {

// accuracy: the local error per step of the fundamental flexible mode.
struct TrapezoidalOptions : ImplicitStepOptions {};

struct TrapezoidalSummary {
  int steps = 0;
  int realizations = 0;
  int newton_iterations = 0;
  int jacobians = 0;
  int factorizations = 0;
  double max_step = 0.0;           // the step bound in use
  double largest_step = 0.0;       // the largest step taken
  double lowest_omega = 0.0;       // rad/s, omega_1 (0: none)
  // Relative frequency error of the trapezoidal rule at omega_1 with the largest step, (omega h)^2/12.
  double lowest_mode_frequency_error() const {
    const double x = lowest_omega * largest_step;
    return x * x / 12.0;
  }
};

class TrapezoidalIntegrator {
 public:
  // `initial` need not be realized. Throws std::invalid_argument for a system with constraints
  // (this method does not project onto constraint manifolds).
  TrapezoidalIntegrator(const SimTK::MultibodySystem& system, const SimTK::State& initial,
                        const TrapezoidalOptions& options = {});

  // Advances to t_end in equal steps of at most max_step. left_limit: the end of the last step is
  // evaluated at t_end^- (an input jumps there); the state is then re-realized at t_end.
  void advance_to(double t_end, bool left_limit = false);

  // The current state, realized to Acceleration.
  const SimTK::State& state() const { return state_; }
  double time() const { return state_.getTime(); }
  double max_step() const { return summary_.max_step; }
  const TrapezoidalSummary& summary() const { return summary_; }

 private:
  void refresh_jacobian(const SimTK::State& at);
  const Eigen::PartialPivLU<Eigen::MatrixXd>& newton_matrix(double h);
  void step(double h, bool left_limit);
  void realize(SimTK::State& s) const;

  const SimTK::MultibodySystem& system_;
  const SimTK::SimbodyMatterSubsystem& matter_;
  TrapezoidalOptions options_;
  TrapezoidalSummary summary_;
  SimTK::State state_;       // accepted, realized to Acceleration
  SimTK::State trial_;       // Newton iterate
  Eigen::MatrixXd A_, B_;    // da/d(delta), da/du
  std::map<long long, Eigen::PartialPivLU<Eigen::MatrixXd>> factors_;  // by h in ns
  double u_scale_ = 0.0;     // running max |u|, for the Newton tolerance
  double d_scale_ = 0.0;     // running max |q - q_initial| (same role for positions)
  SimTK::Vector q_initial_;
};

}  // namespace scoleid::model
