#pragma once
// What the truth's implicit fixed-step methods (trapezoidal.h, gauss_legendre.h) share: their
// preconditions, the frequency their step rule follows, the Jacobian blocks their Newton
// iterations use, and a view of Simbody's contiguous state vectors.
#include <string>

#include <Eigen/Dense>
#include <Simbody.h>

namespace scoleid::model::detail {

// Simbody's state vectors are contiguous: read them through Eigen without element accessors.
inline Eigen::Map<const Eigen::VectorXd> view(const SimTK::Vector& v) {
  return {v.size() ? &v[0] : nullptr, v.size()};
}
inline Eigen::Map<Eigen::VectorXd> view_mut(SimTK::Vector& v) {
  return {v.size() ? &v[0] : nullptr, v.size()};
}

// Throws std::invalid_argument naming `method` for a state without mobilities or a system with
// constraints (neither method projects onto constraint manifolds).
void require_unconstrained(const SimTK::MultibodySystem& system, const SimTK::State& initial, const char* method);

// omega_1 of the step rules: the lowest oscillatory mode of the linearisation about the system's
// default state (undeformed, at rest; a spinning or deformed initial state would add slow modes of
// unsprung bodies, e.g. proof masses on sliders, in the accelerated frame); 0 if none. Adds the
// linearisation's realizations to *realizations.
double default_state_omega(const SimTK::MultibodySystem& system, int* realizations);

// A = da/d(delta) (q = q + N delta) and B = da/du at `at`, by the linearisation (4 nu realizations).
void acceleration_jacobian(const SimTK::MultibodySystem& system, const SimTK::State& at, Eigen::MatrixXd& A,
                           Eigen::MatrixXd& B);

// "%.9g"
std::string str(double x);

}  // namespace scoleid::model::detail
