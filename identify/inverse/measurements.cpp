#include "scoleid/identify/inverse/measurements.h"

#include <array>

#include <algorithm>

namespace scoleid::identify {

namespace {
// The interpolant at tt as Σ_a w[a] z(s0 + a): linear for fewer than 4 samples (count 2), else the
// 4-point Lagrange stencil around the interval, shifted inside the range at the ends; clamped
// beyond the ends (count 1).
int stencil(const std::vector<double>& t, double tt, std::size_t& s0, double* w) {
  const std::size_t N = t.size();
  if (N == 1 || tt <= t.front()) {
    s0 = 0;
    w[0] = 1.0;
    return 1;
  }
  if (tt >= t.back()) {
    s0 = N - 1;
    w[0] = 1.0;
    return 1;
  }
  const auto it = std::upper_bound(t.begin(), t.end(), tt);
  const std::size_t j = static_cast<std::size_t>(it - t.begin());  // t[j-1] <= tt < t[j]
  if (N < 4) {
    const double a = (tt - t[j - 1]) / (t[j] - t[j - 1]);
    s0 = j - 1;
    w[0] = 1 - a;
    w[1] = a;
    return 2;
  }
  s0 = j >= 2 ? j - 2 : 0;
  if (s0 + 4 > N) s0 = N - 4;
  for (int a = 0; a < 4; ++a) {
    double l = 1.0;
    for (int b = 0; b < 4; ++b)
      if (b != a) l *= (tt - t[s0 + static_cast<std::size_t>(b)]) / (t[s0 + static_cast<std::size_t>(a)] - t[s0 + static_cast<std::size_t>(b)]);
    w[a] = l;
  }
  return 4;
}
}  // namespace

void Measurements::eval(double tt, double* out) const {
  const int ns = sensors();
  std::size_t s0 = 0;
  double w[4];
  const int m = stencil(t, tt, s0, w);
  for (int k = 0; k < ns; ++k) {
    double v = 0.0;
    for (int a = 0; a < m; ++a) v += w[a] * z(static_cast<Eigen::Index>(s0 + static_cast<std::size_t>(a)), k);
    out[k] = v;
  }
}

namespace {
// Calls f(weight, s0, w, m) at the 5-point Gauss–Legendre nodes of every sample interval within
// [t0, T] with the interpolant's stencil there (the products of two stencil weights are
// polynomials of degree 6 on an interval, which the rule integrates exactly).
template <class F>
void for_each_node(const std::vector<double>& t, double t0, double T, F&& f, std::size_t first = 0) {
  static const double gx[5] = {0.04691007703066800, 0.2307653449471585, 0.5, 0.7692346550528415, 0.9530899229693320};
  static const double gw[5] = {0.1184634425280945, 0.2393143352496832, 0.2844444444444444, 0.2393143352496832, 0.1184634425280945};
  for (std::size_t i = first; i + 1 < t.size(); ++i) {
    if (t[i] >= T) break;
    const double a = std::max(t[i], t0), b = std::min(t[i + 1], T);
    if (!(b > a)) continue;
    for (int g = 0; g < 5; ++g) {
      std::size_t s0 = 0;
      double w[4];
      const int m = stencil(t, a + gx[g] * (b - a), s0, w);
      f(gw[g] * (b - a), s0, w, m);
    }
  }
}
}  // namespace

double Measurements::white_noise_integral(double t0, double T) const {
  // ∫ Σ_a w_a(t)² dt.
  double sum = 0.0;
  for_each_node(t, t0, T, [&](double wt, std::size_t, const double* w, int m) {
    for (int k = 0; k < m; ++k) sum += wt * w[k] * w[k];
  });
  return sum;
}

std::vector<double> Measurements::white_noise_integral_profile() const {
  // The sum of white_noise_integral's interval contributions, interval by interval.
  std::vector<double> W(t.size(), 0.0);
  for (std::size_t i = 1; i < t.size(); ++i) {
    double sum = 0.0;
    for_each_node(t, t[i - 1], t[i], [&](double wt, std::size_t, const double* w, int m) {
      for (int k = 0; k < m; ++k) sum += wt * w[k] * w[k];
    }, i - 1);
    W[i] = W[i - 1] + sum;
  }
  return W;
}

double Measurements::white_noise_integral_variance(double t0, double T) const {
  // Q is banded: a stencil spans 4 consecutive samples, so |a − b| <= 3. Row a holds Q_{a, a+d}, d = 0..3.
  std::vector<std::array<double, 4>> Q(t.size(), {0.0, 0.0, 0.0, 0.0});
  for_each_node(t, t0, T, [&](double wt, std::size_t s0, const double* w, int m) {
    for (int p = 0; p < m; ++p)
      for (int q = p; q < m; ++q) Q[s0 + static_cast<std::size_t>(p)][static_cast<std::size_t>(q - p)] += wt * w[p] * w[q];
  });
  double sum = 0.0;
  for (const auto& row : Q) sum += row[0] * row[0] + 2.0 * (row[1] * row[1] + row[2] * row[2] + row[3] * row[3]);
  return 2.0 * sum;
}

}  // namespace scoleid::identify
