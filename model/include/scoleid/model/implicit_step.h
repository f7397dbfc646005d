#pragma once
// What the truth's implicit fixed-step methods (trapezoidal.h, gauss_legendre.h) share in their
// interface: the options of their step rule and simplified Newton iteration, and how a span is
// cut into equal steps.
#include <string>

namespace scoleid::model {

struct ImplicitStepOptions {
  double accuracy = 1e-9;          // phase error per step of the fundamental flexible mode
  // Newton tolerance = newton_fraction * accuracy (relative to the running state scale; not below
  // 1e-13, the residual's round-off): below the truncation error, since the residual left in each
  // step accumulates over the run. Measured on SCOLE with the trapezoidal rule: the first correction
  // from y0 is ~3e-8 of the state scale, the next ~1e-12, so this costs about two evaluations per
  // step; 1e-2 instead of 1e-1 costs 2.5 and changed neither the energy drift nor the momentum change.
  double newton_fraction = 1e-1;
  double max_step = 0.0;           // s; 0 = from accuracy and omega_1
  double reference_omega = 0.0;    // omega_1 [rad/s]; 0 = lowest oscillatory mode of the default state
  int max_newton_iterations = 6;   // per step, before the Jacobian is refreshed (twice at most)
  double refresh_contraction = 0.3;  // refresh the Jacobian when successive corrections shrink slower
  bool IsValid(std::string* why) const;
};

// The step bound: options.max_step if given, else phase / omega_1 (phase = omega_1 h at which the
// method's phase error per step is `accuracy`), unbounded without an oscillatory mode.
double implicit_step_bound(const ImplicitStepOptions& options, double omega_1, double phase);

// The number of equal steps of at most max_step that cover span (at least one).
long long equal_steps(double span, double max_step);

}  // namespace scoleid::model
