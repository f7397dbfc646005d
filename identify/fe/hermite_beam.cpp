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

// ∫_a^b f fᵀ ds of a basis f(s) by the 4-point Gauss rule: exact to degree 7.
template <class Basis>
Mat4 gram(double a, double b, Basis f) {
  Mat4 m = Mat4::Zero();
  for (int g = 0; g < 4; ++g) {
    const Vec4 v = f(a + (b - a) * kX[g]);
    m += (b - a) * kW[g] * v * v.transpose();
  }
  return m;
}
}  // namespace

Mat4 mass(double h, double a, double b) {
  return gram(a, b, [h](double s) { return shape(s / h, h); });
}

Mat4 stiffness(double h, double a, double b) {
  return gram(a, b, [h](double s) { return curvature(s / h, h); });
}

// N' N'ᵀ is of degree 4: the 4-point rule is exact.
Mat4 slope_product(double h, double a, double b) {
  return gram(a, b, [h](double s) { return slope(s / h, h); });
}

}  // namespace scoleid::identify::hermite
