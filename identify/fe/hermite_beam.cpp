#include "scoleid/identify/fe/hermite_beam.h"

#include <array>

namespace scoleid::identify::hermite {

Vec4 shape(double x, double h) {
  return {1.0 - 3.0 * x * x + 2.0 * x * x * x, h * (x - 2.0 * x * x + x * x * x), 3.0 * x * x - 2.0 * x * x * x,
          h * (x * x * x - x * x)};
}

Vec4 slope(double x, double h) {
  return {(-6.0 * x + 6.0 * x * x) / h, 1.0 - 4.0 * x + 3.0 * x * x, (6.0 * x - 6.0 * x * x) / h,
          3.0 * x * x - 2.0 * x};
}

Vec4 curvature(double x, double h) {
  return {(-6.0 + 12.0 * x) / (h * h), (-4.0 + 6.0 * x) / h, (6.0 - 12.0 * x) / (h * h), (6.0 * x - 2.0) / h};
}

namespace {
// 4-point Gauss–Legendre on [0, 1]: exact to degree 7 (N Nᵀ is degree 6).
constexpr std::array<double, 4> kX = {0.0694318442029737, 0.3300094782075719, 0.6699905217924281,
                                      0.9305681557970263};
constexpr std::array<double, 4> kW = {0.1739274225687269, 0.3260725774312731, 0.3260725774312731,
                                      0.1739274225687269};
}  // namespace

Mat4 mass(double h, double a, double b) {
  Mat4 m = Mat4::Zero();
  for (int g = 0; g < 4; ++g) {
    const double s = a + (b - a) * kX[g];
    const Vec4 n = shape(s / h, h);
    m += (b - a) * kW[g] * n * n.transpose();
  }
  return m;
}

Mat4 stiffness(double h, double a, double b) {
  Mat4 k = Mat4::Zero();
  for (int g = 0; g < 4; ++g) {
    const double s = a + (b - a) * kX[g];
    const Vec4 c = curvature(s / h, h);
    k += (b - a) * kW[g] * c * c.transpose();
  }
  return k;
}

Mat4 slope_product(double h, double a, double b) {
  // N' N'ᵀ is of degree 4: the 4-point rule is exact.
  Mat4 m = Mat4::Zero();
  for (int g = 0; g < 4; ++g) {
    const double s = a + (b - a) * kX[g];
    const Vec4 d = slope(s / h, h);
    m += (b - a) * kW[g] * d * d.transpose();
  }
  return m;
}

}  // namespace scoleid::identify::hermite
