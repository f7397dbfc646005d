#pragma once
// Finite rotations by the rotation vector φ = angle · axis (docs/theory.md §3.8):
//   R(φ) = exp([φ]×) = I + (sin θ/θ)[φ]× + ((1 − cos θ)/θ²)[φ]×²,  θ = |φ|   (Rodrigues)
//   body angular velocity Ω (Ṙ = R[Ω]×) and φ̇:  Ω = J_r(φ) φ̇,
//   J_r(φ)   = I − ((1 − cos θ)/θ²)[φ]× + ((θ − sin θ)/θ³)[φ]×²,
//   J_r(φ)⁻¹ = I + ½[φ]× + (1/θ² − (1 + cos θ)/(2θ sin θ))[φ]×².
// Regular for θ < 2π (the slews here stay far below); the coefficients switch to their Taylor
// series below θ = 1e-4, where the closed forms lose digits.
#include <Eigen/Dense>

namespace scoleid::identify {

// [v]× w = v × w.
Eigen::Matrix3d skew(const Eigen::Vector3d& v);
Eigen::Matrix3d rotation_matrix(const Eigen::Vector3d& phi);
Eigen::Matrix3d right_jacobian(const Eigen::Vector3d& phi);
Eigen::Matrix3d right_jacobian_inverse(const Eigen::Vector3d& phi);

}  // namespace scoleid::identify
