#pragma once
// Shared by the parts of the nonlinear SCOLE model (scole_nonlinear.h), one concept per file:
// kinematics.cpp, assembly.cpp, foreshortening.cpp, dynamics.cpp, mass.cpp, equations.cpp.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "scoleid/identify/fe/rotation_vector.h"
#include "scoleid/identify/fe/scole_nonlinear.h"

namespace scoleid::identify {

// x on the columns cols, in their order.
inline VectorXd gather_cols(const std::vector<int>& cols, const VectorXd& x) {
  VectorXd g(static_cast<Eigen::Index>(cols.size()));
  for (std::size_t k = 0; k < cols.size(); ++k) g[static_cast<Eigen::Index>(k)] = x[cols[k]];
  return g;
}

}  // namespace scoleid::identify
