// The Hencky bar-chain lumping (model/hencky.h) in Simbody: natural frequencies from the
// numerical linearisation converge to the Euler–Bernoulli values at O(1/n^2), shown as a rate
// from successive halvings of the segment length, and the first three modes are within 0.5 %
// at the default n = 40.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "scoleid/model/beam_chain.h"
#include "scoleid/model/hencky.h"
#include "scoleid/model/linearisation.h"
#include "scoleid/model/truth_run.h"

using namespace scoleid;
using namespace scoleid::model;

namespace {

constexpr double kL = 10.0, kRhoA = 67.0, kEI = 23000.0;

io::BeamSpec beam(io::EndCondition left, io::EndCondition right, double tip_mass = 0, double tip_inertia = 0) {
  io::BeamSpec b;
  b.length = kL;
  b.left = left;
  b.right = right;
  b.rho_A = kRhoA;
  b.EI = {kEI};
  b.zeta = 0.0;
  b.c_kv = 0.0;
  b.tip_mass = tip_mass;
  b.tip_inertia = tip_inertia;
  return b;
}

std::vector<double> chain_omegas(const io::BeamSpec& b, int n, int count) {
  BeamChain chain(b, n);
  chain.system().realizeTopology();
  const auto modes = natural_modes(chain.system(), chain.system().getDefaultState());
  std::vector<double> w;
  for (int k = 0; k < count && k < static_cast<int>(modes.size()); ++k) w.push_back(modes[static_cast<std::size_t>(k)].omega);
  return w;
}

double omega_of_beta(double beta) { return beta * beta * std::sqrt(kEI / kRhoA); }

// Roots of f(beta) on (0, beta_max], by scanning and bisection.
std::vector<double> roots(const std::function<double(double)>& f, double beta_max, int count) {
  std::vector<double> r;
  const int N = 20000;
  double a = 1e-6, fa = f(a);
  for (int i = 1; i <= N && static_cast<int>(r.size()) < count; ++i) {
    const double b = beta_max * i / N, fb = f(b);
    if (fa * fb < 0) {
      double lo = a, hi = b;
      for (int it = 0; it < 200; ++it) {
        const double mid = 0.5 * (lo + hi);
        (f(lo) * f(mid) <= 0 ? hi : lo) = mid;
      }
      r.push_back(0.5 * (lo + hi));
    }
    a = b;
    fa = fb;
  }
  return r;
}

// Cantilever with a tip body (mass M, rotary inertia J about the tip): w = A(ch - c) + B(sh - s),
// tip conditions EI w'' = J w^2 w', EI w''' = -M w^2 w; the determinant of the 2x2 system.
double tip_body_determinant(double beta, double M, double J) {
  const double x = beta * kL, ch = std::cosh(x), c = std::cos(x), sh = std::sinh(x), s = std::sin(x);
  const double w2 = std::pow(omega_of_beta(beta), 2);
  const double b = beta, b2 = b * b, b3 = b2 * b;
  // Row 1: EI w'' - J w^2 w'; row 2: EI w''' + M w^2 w; columns A, B.
  const double a11 = kEI * b2 * (ch + c) - J * w2 * b * (sh + s);
  const double a12 = kEI * b2 * (sh + s) - J * w2 * b * (ch - c);
  const double a21 = kEI * b3 * (sh - s) + M * w2 * (ch - c);
  const double a22 = kEI * b3 * (ch + c) + M * w2 * (sh - s);
  return (a11 * a22 - a12 * a21) / std::pow(ch, 2);  // scaled: the same roots, bounded values
}

struct Case {
  const char* name;
  io::BeamSpec spec;
  std::vector<double> analytic;  // rad/s
  // Observed order. Simply supported is superconvergent: the chain's modes are exact sines and
  // the O(h^2) errors of the joint springs (central 4th difference) and of the bars' consistent
  // mass cancel, leaving O(h^4). Clamped and free ends (and tip bodies) are O(h^2).
  double order;
};

std::vector<Case> cases() {
  const double pi = 3.14159265358979323846;
  std::vector<Case> cs;
  cs.push_back({"cantilever", beam(io::EndCondition::Clamped, io::EndCondition::Free),
                {omega_of_beta(1.8751040687119611 / kL), omega_of_beta(4.6940911329741746 / kL),
                 omega_of_beta(7.8547574382376126 / kL)}, 2.0});
  cs.push_back({"simply supported", beam(io::EndCondition::Pinned, io::EndCondition::Pinned),
                {omega_of_beta(pi / kL), omega_of_beta(2 * pi / kL), omega_of_beta(3 * pi / kL)}, 4.0});
  const double M = 0.5 * kRhoA * kL, J = 0.05 * kRhoA * kL * kL * kL;
  std::vector<double> w;
  for (double beta : roots([&](double b) { return tip_body_determinant(b, M, J); }, 12.0 / kL, 3))
    w.push_back(omega_of_beta(beta));
  cs.push_back({"cantilever + tip mass and rotary inertia",
                beam(io::EndCondition::Clamped, io::EndCondition::Free, M, J), w, 2.0});
  return cs;
}

}  // namespace

TEST(HenckyLumping, JointSpringsAreDualCellCompliances) {
  // Uniform: EI/h inside, 2EI/h at the ends; a section boundary inside a cell combines in series.
  const auto u = hencky_lumping(4, PiecewiseField{8.0, {2.0}}, PiecewiseField{8.0, {0.0}});
  EXPECT_DOUBLE_EQ(u.stiffness[0], 2.0 * 2.0 / 2.0);
  EXPECT_DOUBLE_EQ(u.stiffness[2], 2.0 / 2.0);
  EXPECT_DOUBLE_EQ(u.damping[2], 0.0);
  // L = 4, EI = 1 on [0, 2), 4 on [2, 4]; h = 1: joint 2's cell [1.5, 2.5] straddles the boundary.
  const auto p = hencky_lumping(4, PiecewiseField{4.0, {1.0, 4.0}}, PiecewiseField{4.0, {0.0}});
  EXPECT_DOUBLE_EQ(p.stiffness[1], 1.0);
  EXPECT_DOUBLE_EQ(p.stiffness[2], 1.0 / (0.5 / 1.0 + 0.5 / 4.0));
  EXPECT_DOUBLE_EQ(p.stiffness[4], 2.0 * 4.0);
}

TEST(HenckyChain, FrequenciesConvergeAtSecondOrder) {
  const std::vector<int> ns = {10, 20, 40, 80};
  for (const Case& c : cases()) {
    ASSERT_EQ(c.analytic.size(), 3u) << c.name;
    std::vector<std::vector<double>> err;  // [n][mode]
    for (int n : ns) {
      const auto w = chain_omegas(c.spec, n, 3);
      ASSERT_EQ(w.size(), 3u) << c.name << " n=" << n;
      std::vector<double> e;
      for (int k = 0; k < 3; ++k) e.push_back(std::abs(w[static_cast<std::size_t>(k)] / c.analytic[static_cast<std::size_t>(k)] - 1.0));
      err.push_back(e);
    }
    std::printf("%s: relative frequency error (rate = log2 of successive ratios)\n", c.name);
    std::printf("   n    mode 1      rate    mode 2      rate    mode 3      rate\n");
    for (std::size_t i = 0; i < ns.size(); ++i) {
      std::printf("%4d", ns[i]);
      for (int k = 0; k < 3; ++k) {
        const auto kk = static_cast<std::size_t>(k);
        std::printf("  %.3e", err[i][kk]);
        if (i > 0) std::printf("  %5.2f", std::log2(err[i - 1][kk] / err[i][kk]));
        else std::printf("       ");
      }
      std::printf("\n");
    }
    // The rate from the last halving whose errors stand clear of the linearisation's own
    // floor (central differences, about 1e-8 relative).
    for (std::size_t k = 0; k < 3; ++k) {
      std::size_t last = ns.size() - 1;
      while (last > 1 && err[last][k] < 1e-7) --last;
      const double rate = std::log2(err[last - 1][k] / err[last][k]);
      EXPECT_NEAR(rate, c.order, 0.2) << c.name << " mode " << k + 1 << " n " << ns[last - 1] << " -> " << ns[last];
      EXPECT_LT(err[2][k], 5e-3) << c.name << " mode " << k + 1 << " at n = 40";
    }
  }
}

// The SCOLE chain (free shuttle, clamped root, reflector on its end cell, proof masses) has no
// closed form; its first flexible frequencies self-converge at second order: the differences
// between successive halvings shrink by 4.
TEST(ScoleChain, FrequenciesSelfConvergeAtSecondOrder) {
  const io::Scenario sc = io::load_scenario("paper-scole-1");
  std::vector<std::vector<double>> f;
  const std::vector<int> ns = {10, 20, 40, 80};
  for (int n : ns) {
    const auto st = prepare_structure(sc, n);
    const auto modes = natural_modes(st->system(), st->system().getDefaultState());
    std::vector<double> w;
    for (std::size_t k = 0; k < 4; ++k) w.push_back(modes.at(k).frequency_hz);
    f.push_back(w);
  }
  std::printf("SCOLE first four frequencies [Hz] and self-convergence rates\n");
  for (std::size_t i = 0; i < ns.size(); ++i) {
    std::printf("%4d", ns[i]);
    for (std::size_t k = 0; k < 4; ++k) std::printf("  %.6f", f[i][k]);
    std::printf("\n");
  }
  for (std::size_t k = 0; k < 4; ++k) {
    const double rate = std::log2((f[1][k] - f[0][k]) / (f[2][k] - f[1][k]));
    const double rate2 = std::log2((f[2][k] - f[1][k]) / (f[3][k] - f[2][k]));
    std::printf("mode %zu: rates %.2f, %.2f; |f40 - f80| / f80 = %.2e\n", k + 1, rate, rate2,
                std::abs(f[2][k] - f[3][k]) / f[3][k]);
    EXPECT_NEAR(rate2, 2.0, 0.2) << "mode " << k + 1;
  }
}
