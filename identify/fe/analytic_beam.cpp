#include "scoleid/identify/fe/analytic_beam.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

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

namespace {

using Z = std::array<std::array<double, 2>, 4>;  // z for each of the left end's two unknowns

// The 2 × 2 determinant of the right end's conditions at ω (see the header), in the scaled field
// ẑ = (w, w_s/β, w_ss/β², w_sss/β³), whose transfer matrix over a stretch a is [[S T U V] [V S T U]
// [U V S T] [T U V S]] of β a. Carried in steps of β a <= 1 with the two columns orthonormalised
// after each (Gram–Schmidt with positive diagonal: the determinant keeps its sign and stays O(1),
// where the plain product would lose it to cancellation between terms of size e^{2βL}).
double end_determinant(const io::BeamSpec& b, const std::vector<io::PointElement>& elems, double w) {
  const double EI = b.EI[0], beta = std::pow(b.rho_A * w * w / EI, 0.25);
  Z z{};
  using io::EndCondition;
  const int free_rows[3][2] = {{1, 3}, {2, 3}, {0, 1}};  // pinned (w_s, Q), clamped (M, Q), free (w, w_s)
  const int* rows = free_rows[b.left == EndCondition::Pinned ? 0 : b.left == EndCondition::Clamped ? 1 : 2];
  z[static_cast<std::size_t>(rows[0])][0] = 1.0;
  z[static_cast<std::size_t>(rows[1])][1] = 1.0;
  auto orthonormalise = [&] {
    double n0 = 0.0, d = 0.0, n1 = 0.0;
    for (int i = 0; i < 4; ++i) n0 += z[static_cast<std::size_t>(i)][0] * z[static_cast<std::size_t>(i)][0];
    n0 = std::sqrt(n0);
    for (auto& r : z) r[0] /= n0;
    for (const auto& r : z) d += r[0] * r[1];
    for (auto& r : z) r[1] -= d * r[0];
    for (const auto& r : z) n1 += r[1] * r[1];
    n1 = std::sqrt(n1);
    for (auto& r : z) r[1] /= n1;
  };
  // A lumped attachment adds its dynamic stiffness at the station, k_l (k_g − m_l ω²)/(k_l + k_g −
  // m_l ω²); the determinant is multiplied by each denominator so that its poles (the lumped mass
  // alone on its springs, the beam held) are no sign changes and its zeros stay the modes.
  double poles = 1.0;
  auto jump = [&](const io::PointElement& e) {
    double lumped = 0.0;
    if (e.lumped_mass > 0.0) {
      const double d = e.lumped_k + e.lumped_k_ground - e.lumped_mass * w * w;
      poles *= d;
      lumped = e.lumped_k * (e.lumped_k_ground - e.lumped_mass * w * w) / d;
    }
    for (int c = 0; c < 2; ++c) {
      z[3][c] += (e.mass * w * w - e.k_w - lumped) / (EI * beta * beta * beta) * z[0][c];
      z[2][c] -= (e.inertia * w * w - e.k_theta) / (EI * beta) * z[1][c];
    }
  };
  auto carry = [&](double a) {
    if (a <= 0.0) return;
    const int steps = std::max(1, static_cast<int>(std::ceil(beta * a)));
    const double x = beta * a / steps, ch = std::cosh(x), sh = std::sinh(x), c = std::cos(x), s = std::sin(x);
    const double S = 0.5 * (ch + c), T = 0.5 * (sh + s), U = 0.5 * (ch - c), V = 0.5 * (sh - s);
    const double t[4][4] = {{S, T, U, V}, {V, S, T, U}, {U, V, S, T}, {T, U, V, S}};
    for (int k = 0; k < steps; ++k) {
      Z out{};
      for (int i = 0; i < 4; ++i)
        for (int col = 0; col < 2; ++col)
          for (int m = 0; m < 4; ++m)
            out[static_cast<std::size_t>(i)][col] += t[i][m] * z[static_cast<std::size_t>(m)][col];
      z = out;
      orthonormalise();
    }
  };
  double at = 0.0;
  for (const auto& e : elems) {
    carry(e.location - at);
    at = std::max(at, e.location);
    jump(e);
  }
  carry(b.length - at);
  const int end_rows[3][2] = {{0, 2}, {0, 1}, {2, 3}};  // pinned (w, M), clamped (w, w_s), free (M, Q)
  const int* r = end_rows[b.right == EndCondition::Pinned ? 0 : b.right == EndCondition::Clamped ? 1 : 2];
  const auto& a = z[static_cast<std::size_t>(r[0])];
  const auto& c = z[static_cast<std::size_t>(r[1])];
  return (a[0] * c[1] - a[1] * c[0]) * poles;
}

}  // namespace

std::vector<double> point_element_omegas(const io::BeamSpec& b, int count) {
  if (b.EI.size() != 1) throw std::invalid_argument("point_element_omegas: a uniform beam (one EI)");
  std::vector<io::PointElement> elems = b.supports;
  elems.insert(elems.end(), b.attachments.begin(), b.attachments.end());
  if (b.tip_mass > 0.0 || b.tip_inertia > 0.0) {
    io::PointElement tip{"tip", b.length};
    tip.mass = b.tip_mass;
    tip.inertia = b.tip_inertia;
    elems.push_back(tip);
  }
  std::stable_sort(elems.begin(), elems.end(), [](const auto& x, const auto& y) { return x.location < y.location; });
  // β L from a thousandth of the first pinned–pinned value in steps of a thousandth of π: the
  // roots of an Euler–Bernoulli beam lie about π apart in β L.
  const double L = b.length, scale = std::sqrt(b.EI[0] / (b.rho_A * L * L * L * L));
  const auto f = [&](double bl) { return end_determinant(b, elems, bl * bl * scale); };
  std::vector<double> bl = roots(f, count, 1e-3 * kPi);
  for (double& x : bl) x = x * x * scale;
  return bl;
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

// The exact frequencies [Hz] of a beam with one EI (its end conditions, tip body and point
// elements), or empty (a tip body on ends other than clamped-free; EI by sections); `what` names
// the solution (crosscheck modes' analytic column).
std::vector<double> beam_hz(const io::BeamSpec& b, int count, std::string& what) {
  what.clear();
  if (b.EI.size() != 1) return {};
  using io::EndCondition;
  const double L = b.length, EI = b.EI[0], rA = b.rho_A;
  std::vector<double> bl;
  auto is = [&](EndCondition l, EndCondition r) {
    return (b.left == l && b.right == r) || (b.left == r && b.right == l);
  };
  const bool tip = b.tip_mass > 0 || b.tip_inertia > 0;
  if (!b.supports.empty() || !b.attachments.empty()) {
    // Supports and attachments: the exact transfer-matrix solution (analytic_beam.h).
    what = "Euler-Bernoulli with supports and attachments (transfer matrix, undamped)";
    std::vector<double> hz;
    for (double w : point_element_omegas(b, count)) hz.push_back(w / (2.0 * M_PI));
    return hz;
  }
  if (is(EndCondition::Clamped, EndCondition::Free) && b.left == EndCondition::Clamped) {
    bl = tip ? beta_L_tip_mass(b.tip_mass / (rA * L), b.tip_inertia / (rA * L * L * L), count)
             : beta_L(Support::ClampedFree, count);
    what = tip ? "Euler-Bernoulli cantilever with tip mass and rotary inertia" : "Euler-Bernoulli clamped-free";
  } else if (tip) {
    return {};
  } else if (is(EndCondition::Pinned, EndCondition::Pinned)) {
    bl = beta_L(Support::PinnedPinned, count);
    what = "Euler-Bernoulli pinned-pinned";
  } else if (is(EndCondition::Clamped, EndCondition::Clamped)) {
    bl = beta_L(Support::ClampedClamped, count);
    what = "Euler-Bernoulli clamped-clamped";
  } else if (is(EndCondition::Free, EndCondition::Free)) {
    bl = beta_L(Support::FreeFree, count);
    what = "Euler-Bernoulli free-free";
  } else if (is(EndCondition::Clamped, EndCondition::Free)) {
    bl = beta_L(Support::ClampedFree, count);
    what = "Euler-Bernoulli clamped-free";
  } else {
    return {};
  }
  std::vector<double> hz;
  for (double x : bl) hz.push_back(omega(x, L, EI, rA) / (2.0 * M_PI));
  return hz;
}

std::vector<double> ss_scenario_samples(const io::Scenario& sc, int terms) {
  using io::EndCondition;
  if (sc.structure != io::Structure::Beam || sc.beam.EI.size() != 1 || sc.beam.left != EndCondition::Pinned ||
      sc.beam.right != EndCondition::Pinned || sc.inputs.empty() || sc.sensors.empty())
    throw std::invalid_argument("ss_scenario_samples: a uniform simply supported beam with an input and a sensor");
  const double dt = sc.simulation.sample_interval;
  const int n = static_cast<int>(std::lround(sc.simulation.duration / dt));
  return ss_step_samples(sc.sensors[0].location, dt, n, sc.inputs[0].location, sc.inputs[0].signal(1.0), sc.beam.length,
                         sc.beam.EI[0], sc.beam.rho_A, terms);
}

}  // namespace scoleid::identify::analytic
