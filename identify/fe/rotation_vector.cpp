#include "scoleid/identify/fe/rotation_vector.h"

#include <cmath>

namespace scoleid::identify {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {
constexpr double kSmallAngle = 1e-4;
}  // namespace

Matrix3d skew(const Vector3d& v) {
  Matrix3d S;
  S << 0.0, -v[2], v[1], v[2], 0.0, -v[0], -v[1], v[0], 0.0;
  return S;
}

Matrix3d rotation_matrix(const Vector3d& phi) {
  const double t = phi.norm(), t2 = t * t;
  const Matrix3d S = skew(phi);
  // sin θ/θ and (1 − cos θ)/θ², with their series for small θ.
  const double a = t < kSmallAngle ? 1.0 - t2 / 6.0 : std::sin(t) / t;
  const double b = t < kSmallAngle ? 0.5 - t2 / 24.0 : (1.0 - std::cos(t)) / t2;
  return Matrix3d::Identity() + a * S + b * S * S;
}

Matrix3d right_jacobian(const Vector3d& phi) {
  const double t = phi.norm(), t2 = t * t;
  const Matrix3d S = skew(phi);
  const double b = t < kSmallAngle ? 0.5 - t2 / 24.0 : (1.0 - std::cos(t)) / t2;
  const double c = t < kSmallAngle ? 1.0 / 6.0 - t2 / 120.0 : (t - std::sin(t)) / (t2 * t);
  return Matrix3d::Identity() - b * S + c * S * S;
}

Matrix3d right_jacobian_inverse(const Vector3d& phi) {
  const double t = phi.norm(), t2 = t * t;
  const Matrix3d S = skew(phi);
  const double d = t < kSmallAngle ? 1.0 / 12.0 + t2 / 720.0 : 1.0 / t2 - (1.0 + std::cos(t)) / (2.0 * t * std::sin(t));
  return Matrix3d::Identity() + 0.5 * S + d * S * S;
}

}  // namespace scoleid::identify
