#include "scoleid/crosscheck/richardson.h"

#include <cmath>
#include <limits>

namespace scoleid::crosscheck {

double observed_order(double f_n, double f_rn, double f_r2n, double ratio, double noise) {
  const double d1 = f_n - f_rn, d2 = f_rn - f_r2n;
  if (std::abs(d1) <= noise && std::abs(d2) <= noise) return std::numeric_limits<double>::quiet_NaN();
  if (d2 == 0.0 || d1 / d2 <= 0.0) return std::numeric_limits<double>::quiet_NaN();
  return std::log(d1 / d2) / std::log(ratio);
}

double richardson(double f_coarse, double f_fine, double ratio, double p) {
  return f_fine + (f_fine - f_coarse) / (std::pow(ratio, p) - 1.0);
}

}  // namespace scoleid::crosscheck
