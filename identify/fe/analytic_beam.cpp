#include "scoleid/identify/fe/analytic_beam.h"

#include <cmath>
#include <functional>

namespace scoleid::identify::analytic {

namespace {
constexpr double kPi = 3.14159265358979323846;

std::vector<double> roots(const std::function<double(double)>& f, int count, double dx = 1e-3) {
  std::vector<double> out;
  double a = dx, fa = f(a);
  while (static_cast<int>(out.size()) < count) {
    const double b = a + dx, fb = f(b);
    if (fa == 0.0) {
      out.push_back(a);
    } else if (fa * fb < 0.0) {
      double lo = a, hi = b, flo = fa;
      for (int it = 0; it < 200 && hi - lo > 4e-16 * hi; ++it) {
        const double mid = 0.5 * (lo + hi), fm = f(mid);
        if ((fm < 0) == (flo < 0)) { lo = mid; flo = fm; } else { hi = mid; }
      }
      out.push_back(0.5 * (lo + hi));
    }
    a = b;
    fa = fb;
  }
  return out;
}
}  // namespace

std::vector<double> beta_L(Support s, int count) {
  switch (s) {
    case Support::PinnedPinned: {
      std::vector<double> r;
      for (int k = 1; k <= count; ++k) r.push_back(k * kPi);
      return r;
    }
    // Divided by cosh to keep the functions O(1) at large arguments.
    case Support::ClampedFree:
      return roots([](double x) { return 1.0 / std::cosh(x) + std::cos(x); }, count);
    case Support::FreeFree:
    case Support::ClampedClamped:
      return roots([](double x) { return 1.0 / std::cosh(x) - std::cos(x); }, count);
  }
  return {};
}

std::vector<double> beta_L_tip_mass(double mu, double j, int count) {
  return roots(
      [mu, j](double l) {
        const double c = std::cos(l), s = std::sin(l), ch = std::cosh(l), sh = std::sinh(l);
        const double f = 1.0 + c * ch + mu * l * (c * sh - s * ch) - j * l * l * l * (s * ch + c * sh) +
                         mu * j * l * l * l * l * (1.0 - c * ch);
        return f / ch;
      },
      count);
}

double omega(double betaL, double L, double EI, double rhoA) {
  return betaL * betaL * std::sqrt(EI / (rhoA * L * L * L * L));
}

double ss_static_point_load(double x, double a, double P, double L, double EI) {
  if (x > a) return ss_static_point_load(L - x, L - a, P, L, EI);
  const double b = L - a;
  return P * b * x * (L * L - b * b - x * x) / (6.0 * EI * L);
}

double cantilever_static_tip_load(double x, double P, double L, double EI) {
  return P * x * x * (3.0 * L - x) / (6.0 * EI);
}

double ss_step_response(double x, double t, double a, double P, double L, double EI, double rhoA, int terms) {
  // Sum from the smallest term up to limit rounding.
  double w = 0.0;
  for (int k = terms; k >= 1; --k) {
    const double wk = omega(k * kPi, L, EI, rhoA);
    w += 2.0 * P / (rhoA * L * wk * wk) * std::sin(k * kPi * a / L) * std::sin(k * kPi * x / L) * (1.0 - std::cos(wk * t));
  }
  return w;
}

std::vector<double> ss_step_samples(double x, double dt, int n, double a, double P, double L, double EI, double rhoA,
                                    int terms) {
  std::vector<double> w;
  for (int k = 0; k <= n; ++k) w.push_back(ss_step_response(x, k * dt, a, P, L, EI, rhoA, terms));
  return w;
}

}  // namespace scoleid::identify::analytic
