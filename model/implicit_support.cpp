#include "implicit_support.h"

#include <cstdio>
#include <stdexcept>

#include "scoleid/model/linearisation.h"

namespace scoleid::model::detail {

void require_unconstrained(const SimTK::MultibodySystem& system, const SimTK::State& initial, const char* method) {
  if (initial.getNU() == 0) throw std::invalid_argument(std::string(method) + ": the system has no mobilities");
  if (system.getMatterSubsystem().getNumConstraints() > 0)
    throw std::invalid_argument(std::string(method) +
                                ": the system has constraints, which this method does not project onto");
}

double default_state_omega(const SimTK::MultibodySystem& system, int* realizations) {
  const SimTK::State rest = system.getDefaultState();
  const Eigen::MatrixXd J0 = state_jacobian(system, rest);
  *realizations += 4 * rest.getNU();
  const auto modes = modes_of(J0, LinearisationOptions{}.zero_tolerance);
  return modes.empty() ? 0.0 : modes.front().omega;
}

void acceleration_jacobian(const SimTK::MultibodySystem& system, const SimTK::State& at, Eigen::MatrixXd& A,
                           Eigen::MatrixXd& B) {
  const int nu = at.getNU();
  const Eigen::MatrixXd J = state_jacobian(system, at);
  A = J.block(nu, 0, nu, nu);
  B = J.block(nu, nu, nu, nu);
}

std::string str(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.9g", x);
  return b;
}

}  // namespace scoleid::model::detail
