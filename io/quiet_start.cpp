#include "scoleid/io/quiet_start.h"

#include <algorithm>
#include <cmath>

namespace scoleid::io {

std::size_t trigger_sample(const double* x, std::size_t n) {
  double peak = 0.0;
  for (std::size_t i = 0; i < n; ++i) peak = std::max(peak, std::abs(x[i]));
  if (!(peak > 0)) return n;
  for (std::size_t i = 0; i < n; ++i)
    if (std::abs(x[i]) > 0.05 * peak) return i;
  return n;
}

std::size_t quiet_samples(std::size_t trigger) {
  return trigger < static_cast<std::size_t>(kQuietSamples + kQuietMargin) ? 0 : trigger - kQuietMargin;
}

double quiet_start_noise(const double* y, std::size_t quiet) {
  if (quiet < 2) return 0.0;
  const double q = static_cast<double>(quiet);
  double mean = 0.0;
  for (std::size_t i = 0; i < quiet; ++i) mean += y[i] / q;
  double var = 0.0, diff = 0.0;
  for (std::size_t i = 0; i < quiet; ++i) var += std::pow(y[i] - mean, 2) / (q - 1.0);
  for (std::size_t i = 1; i < quiet; ++i) diff += std::pow(y[i] - y[i - 1], 2) / (2.0 * (q - 1.0));
  const double sd = std::sqrt(std::min(var, diff));
  return sd > 0 && std::isfinite(sd) ? sd : 0.0;
}

}  // namespace scoleid::io
