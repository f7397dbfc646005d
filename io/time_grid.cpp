#include "scoleid/io/time_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "scoleid/io/error.h"

namespace scoleid::io {

namespace {

// Does printing x with `format` and `digits` and reading it back give x?
bool reproduces(double x, const char* format, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, digits, x);
  return std::strtod(buf, nullptr) == x;
}

// The fewest digits (1..17) with which format reproduces every sampled time; 0 when none does.
int fewest_digits(const std::vector<double>& t, const char* format, int most) {
  const std::size_t n = t.size(), stride = std::max<std::size_t>(1, n / 4096);
  for (int d = 0; d <= most; ++d) {
    bool all = true;
    for (std::size_t k = 0; k < n && all; k += stride) all = reproduces(t[k], format, d);
    if (all && reproduces(t[n - 1], format, d)) return d;
  }
  return -1;
}

}  // namespace

std::vector<double> TimeGrid::times(std::size_t n) const {
  std::vector<double> g(n);
  for (std::size_t k = 0; k < n; ++k) g[k] = t0 + static_cast<double>(k) * step;
  return g;
}

TimeGrid uniform_grid(const std::vector<double>& t) {
  TimeGrid g;
  const std::size_t n = t.size();
  if (n < 2) return g;
  // Least squares t_k ≈ a + b (k − k̄), in long double (k² sums of millions of samples).
  const long double kbar = static_cast<long double>(n - 1) / 2;
  long double tbar = 0, skk = 0, skt = 0;
  for (std::size_t k = 0; k < n; ++k) tbar += t[k];
  tbar /= static_cast<long double>(n);
  for (std::size_t k = 0; k < n; ++k) {
    const long double dk = static_cast<long double>(k) - kbar;
    skk += dk * dk;
    skt += dk * (static_cast<long double>(t[k]) - tbar);
  }
  const long double b = skt / skk, a = tbar - b * kbar;
  g.step = static_cast<double>(b);
  g.t0 = static_cast<double>(a);
  for (std::size_t k = 0; k < n; ++k) {
    const double shift = std::abs(t[k] - static_cast<double>(a + b * static_cast<long double>(k)));
    if (shift > g.max_shift) {
      g.max_shift = shift;
      g.worst = k;
    }
  }
  // Already uniform to the arithmetic of the times themselves: nothing written coarsely.
  const double tmax = std::max(std::abs(t.front()), std::abs(t.back()));
  if (g.max_shift <= 1e-12 * std::max(tmax, g.step) + 1e-9 * g.step) {
    g.uniform = true;
    g.precision = "full";
    return g;
  }
  // The written precision, by significant digits and by decimals.
  const int sig = fewest_digits(t, "%.*g", 17), dec = fewest_digits(t, "%.*f", 12);
  if (sig >= 0 && (dec < 0 || sig <= dec)) g.precision = std::to_string(sig) + " significant digits";
  else if (dec >= 0) g.precision = std::to_string(dec) + " decimals";
  else g.precision = "full";
  // The fitted line's own standard error at k, s·√(1/n + (k − k̄)²/Σ(k − k̄)²): where the rounding is
  // finest (small t, written to significant digits) the grid is known no better than that.
  long double ss = 0;
  for (std::size_t k = 0; k < n; ++k) ss += std::pow(static_cast<long double>(t[k]) - (a + b * static_cast<long double>(k)), 2);
  const double s2 = n > 2 ? static_cast<double>(ss / static_cast<long double>(n - 2)) : 0.0;
  // Rounding that moves a sample by a quarter of a step or more leaves no clock to recognise.
  g.uniform = g.max_shift < 0.25 * g.step;
  for (std::size_t k = 0; k < n && g.uniform; ++k) {
    const double dk = static_cast<double>(k) - static_cast<double>(kbar);
    const double se = std::sqrt(s2 * (1.0 / static_cast<double>(n) + dk * dk / static_cast<double>(skk)));
    const double x = std::abs(t[k]);
    double half_unit = 0.0;
    if (sig > 0 && x > 0) half_unit = 0.5 * std::pow(10.0, std::floor(std::log10(x)) - (sig - 1));
    if (dec >= 0) half_unit = std::max(half_unit, 0.5 * std::pow(10.0, -dec));
    const double shift = std::abs(t[k] - static_cast<double>(a + b * static_cast<long double>(k)));
    if (shift > 1.05 * half_unit + 3.0 * se + 1e-9 * g.step) {
      g.uniform = false;
      break;
    }
  }
  return g;
}

std::optional<TimeGrid> stated_grid(const std::vector<double>& t, double rate, std::string* why, double stated_step,
                                     double rounding) {
  TimeGrid g;
  g.step = 1.0 / rate;
  g.t0 = t.front();
  g.precision = "stated rate";
  if (stated_step > 0 && std::abs(g.step - stated_step) <= rounding * (1 + 1e-12)) {
    // The file's own times are t0 + k·stated_step: the rate is what that written step rounds.
    g.precision = "stated rate (the file's step " + format_value(stated_step) + " s as written)";
    for (std::size_t k = 0; k < t.size(); ++k) {
      const double shift = std::abs(t[k] - (g.t0 + static_cast<double>(k) * g.step));
      if (shift > g.max_shift) g.max_shift = shift, g.worst = k;
    }
    g.uniform = true;
    return g;
  }
  for (std::size_t k = 0; k < t.size(); ++k) {
    const double shift = std::abs(t[k] - (g.t0 + static_cast<double>(k) * g.step));
    if (shift > g.max_shift) {
      g.max_shift = shift;
      g.worst = k;
    }
  }
  if (g.max_shift >= 0.5 * g.step) {
    if (why) {
      char buf[256];
      std::snprintf(buf, sizeof buf, "sample %zu at %.9g s lies %.3g steps off the uniform grid from %.9g s (%zu samples over %.6g s are %.6g Hz)",
                    g.worst + 1, t[g.worst], g.max_shift / g.step, g.t0, t.size(), t.back() - t.front(),
                    (static_cast<double>(t.size()) - 1) / (t.back() - t.front()));
      *why = buf;
    }
    return std::nullopt;
  }
  g.uniform = true;
  return g;
}

}  // namespace scoleid::io
