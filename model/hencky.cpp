#include "scoleid/model/hencky.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace scoleid::model {

double PiecewiseField::at(double s) const {
  const int n = static_cast<int>(values.size());
  const int k = std::clamp(static_cast<int>(std::floor(s / length * n)), 0, n - 1);
  return values[static_cast<std::size_t>(k)];
}

double PiecewiseField::integral_of_inverse(double a, double b) const {
  const int n = static_cast<int>(values.size());
  const double w = length / n;
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const double lo = std::max(a, k * w), hi = std::min(b, (k + 1) * w);
    if (hi > lo) sum += (hi - lo) / values[static_cast<std::size_t>(k)];
  }
  return sum;
}

namespace {
// 1 / integral of 1/f over the cell: the series combination of the cell's pieces. A field that
// is zero anywhere in the cell (no damping) gives 0.
double series(const PiecewiseField& f, double a, double b) {
  for (double v : f.values)
    if (!(v > 0.0)) return 0.0;
  return 1.0 / f.integral_of_inverse(a, b);
}
}  // namespace

HenckyLumping hencky_lumping(int segments, const PiecewiseField& rigidity,
                             const PiecewiseField& damping_coefficient) {
  if (segments < 1) throw std::invalid_argument("hencky_lumping: segments must be >= 1");
  HenckyLumping out;
  out.segments = segments;
  const double L = rigidity.length;
  out.h = L / segments;
  out.stiffness.resize(static_cast<std::size_t>(segments) + 1);
  out.damping.resize(static_cast<std::size_t>(segments) + 1);
  for (int j = 0; j <= segments; ++j) {
    const double a = std::max(0.0, (j - 0.5) * out.h), b = std::min(L, (j + 0.5) * out.h);
    out.stiffness[static_cast<std::size_t>(j)] = series(rigidity, a, b);
    out.damping[static_cast<std::size_t>(j)] = series(damping_coefficient, a, b);
  }
  return out;
}

}  // namespace scoleid::model
