#pragma once
// Numerical linearisation of a Simbody system about an equilibrium, and its modes.
//
// Coordinates x = (delta, u), with q = q0 + N(q0) delta (N the kinematic matrix qdot = N u, so
// quaternions stay meaningful and delta_dot = u at the expansion point). The state-derivative
// Jacobian
//     A = [ 0        I      ]
//         [ du/dd    du/du  ]   (udot from realize(Acceleration), constraints included)
// is formed by central differences with step `step` in every delta and u. Its eigenvalues
// lambda give the natural frequencies |lambda| / 2 pi and damping ratios -Re(lambda)/|lambda|.
// Constraint-violating directions and rigid-body motions give (near-)zero eigenvalues; modes
// with |lambda| <= zero_tolerance or Im(lambda) <= 0 are not reported. Central differences make
// the error O(step^2) in the nonlinearity plus O(eps/step) round-off.
#include <vector>

#include <Eigen/Dense>
#include <Simbody.h>

namespace scoleid::model {

struct LinearisationOptions {
  double step = 1e-6;
  double zero_tolerance = 1e-3;   // rad/s
  bool IsValid(std::string* why) const;
};

struct Mode {
  double frequency_hz = 0.0;
  double omega = 0.0;          // |lambda|, rad/s
  double damping_ratio = 0.0;
};

// udot at `state` (realized to Acceleration here).
Eigen::VectorXd generalized_accelerations(const SimTK::MultibodySystem& system, const SimTK::State& state);

// The 2 nu x 2 nu state-derivative Jacobian at `equilibrium`.
Eigen::MatrixXd state_jacobian(const SimTK::MultibodySystem& system, const SimTK::State& equilibrium,
                               const LinearisationOptions& options = {});

// Oscillatory modes sorted by frequency.
std::vector<Mode> natural_modes(const SimTK::MultibodySystem& system, const SimTK::State& equilibrium,
                                const LinearisationOptions& options = {});
std::vector<Mode> modes_of(const Eigen::MatrixXd& A, double zero_tolerance);

// Newton iteration for a static equilibrium udot = 0, u = 0 over the listed mobilities (others
// held at their values): q = q0 + N delta, delta restricted to `mobilities`. Returns the final
// max |udot| over them.
double solve_static_equilibrium(const SimTK::MultibodySystem& system, SimTK::State& state,
                                const std::vector<int>& mobilities, int max_iterations = 20,
                                double tolerance = 1e-10);

}  // namespace scoleid::model
