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
// with Im(lambda) <= 0 or |lambda| below max(zero_tolerance, 30 sqrt(eps max_j |du_dot_j/d delta_j|))
// (the round-off level of the differenced accelerations, which grows with a chain's stiffness)
// are not reported. Central differences make
// the error O(step^2) in the nonlinearity plus O(eps/step) round-off.
#include <functional>
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

// Undamped modes with their shapes. At an equilibrium with u = 0 the velocity-dependent forces
// (dampers) do not enter du_dot/d delta, so the undamped eigenproblem is
//     -(du_dot/d delta) phi = omega^2 phi,
// whose eigenvalues are real and >= 0 (M^-1 K in the coordinates delta); without constraints it is
// solved as the symmetric-definite (M K_delta) phi = omega^2 M phi. Rigid-body motions and
// constraint-violating directions (omega below max(zero_tolerance, 30 sqrt(eps max K_ii)), the
// round-off level of the differenced accelerations) are dropped. A mode's shape is
// reported through `outputs` (any read-out of a position-realized state, e.g. sensor values):
// the column (dy/d delta) phi, by central differences, normalised to unit 2-norm with its largest
// entry positive.
struct ModeShapes {
  Eigen::VectorXd omega;   // rad/s, ascending
  Eigen::MatrixXd shapes;  // outputs x modes
};
using OutputFunction = std::function<Eigen::VectorXd(const SimTK::State&)>;
ModeShapes undamped_modes(const SimTK::MultibodySystem& system, const SimTK::State& equilibrium,
                          const OutputFunction& outputs, const LinearisationOptions& options = {});

// Newton iteration for a static equilibrium udot = 0, u = 0 over the listed mobilities (others
// held at their values): q = q0 + N delta, delta restricted to `mobilities`. Returns the final
// max |udot| over them.
double solve_static_equilibrium(const SimTK::MultibodySystem& system, SimTK::State& state,
                                const std::vector<int>& mobilities, int max_iterations = 20,
                                double tolerance = 1e-10);

}  // namespace scoleid::model
