#include "scoleid/identify/inverse/measurements.h"

#include <algorithm>

namespace scoleid::identify {

void Measurements::eval(double tt, double* out) const {
  const int ns = sensors();
  const std::size_t N = t.size();
  if (N == 1 || tt <= t.front()) {
    for (int k = 0; k < ns; ++k) out[k] = z(0, k);
    return;
  }
  if (tt >= t.back()) {
    for (int k = 0; k < ns; ++k) out[k] = z(static_cast<Eigen::Index>(N - 1), k);
    return;
  }
  const auto it = std::upper_bound(t.begin(), t.end(), tt);
  const std::size_t j = static_cast<std::size_t>(it - t.begin());  // t[j-1] <= tt < t[j]
  if (N < 4) {
    const double a = (tt - t[j - 1]) / (t[j] - t[j - 1]);
    for (int k = 0; k < ns; ++k)
      out[k] = (1 - a) * z(static_cast<Eigen::Index>(j - 1), k) + a * z(static_cast<Eigen::Index>(j), k);
    return;
  }
  // Stencil of 4 samples around the interval, shifted inside the range at the ends.
  std::size_t s0 = j >= 2 ? j - 2 : 0;
  if (s0 + 4 > N) s0 = N - 4;
  double w[4];
  for (int a = 0; a < 4; ++a) {
    double l = 1.0;
    for (int b = 0; b < 4; ++b)
      if (b != a) l *= (tt - t[s0 + static_cast<std::size_t>(b)]) / (t[s0 + static_cast<std::size_t>(a)] - t[s0 + static_cast<std::size_t>(b)]);
    w[a] = l;
  }
  for (int k = 0; k < ns; ++k) {
    double v = 0.0;
    for (int a = 0; a < 4; ++a) v += w[a] * z(static_cast<Eigen::Index>(s0 + static_cast<std::size_t>(a)), k);
    out[k] = v;
  }
}

}  // namespace scoleid::identify
