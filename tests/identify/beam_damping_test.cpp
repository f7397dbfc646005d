// The beam's two damping laws (docs/theory.md §2.2): square-root (Chen–Russell) damping
// −(d w_st)_s, d = 2ζ√(ρA·EI), ζ dimensionless, and Kelvin–Voigt (c_kv w_sst)_ss.
//   1. Exact damped modes of the FE model (damped_modes): on a uniform pinned–pinned beam every
//      mode has damping ratio ζ and damped frequency ω_k√(1−ζ²); Kelvin–Voigt adds c_kv ω_k/(2EI).
//   2. The slope-product element matrix G = ∫ N′N′ᵀ ds against its closed form, and the
//      assembled G against ∫ w′² ds of a sine.
//   3. Negative zeta or c_kv is refused naming the field and the value.
// (Their gradients, against FD and the CVODES adjoint: tests/identify/gradient_test.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "test_support.h"
#include "scoleid/identify/fe/beam_model.h"
#include "scoleid/identify/fe/hermite_beam.h"
#include "scoleid/identify/fe/modal.h"
#include "scoleid/identify/run/problem.h"
#include "scoleid/io/error.h"

using namespace scoleid;
using namespace scoleid::identify;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kL = 10.0, kRhoA = 67.0, kEI = 23000.0;

io::BeamSpec pinned_beam() {
  io::BeamSpec b;
  b.length = kL;
  b.left = b.right = io::EndCondition::Pinned;
  b.rho_A = kRhoA;
  b.EI = {kEI};
  return b;
}

std::vector<DampedMode> fe_damped_modes(int elements, double zeta, double c_kv) {
  const BeamFE fe = build_beam(pinned_beam(), elements, 1, {}, {});
  const AssembledModel a = assemble(fe.model, beam_coefficients(fe, kRhoA, {kEI}, zeta, c_kv));
  return damped_modes(MatrixXd(a.M), MatrixXd(a.D), MatrixXd(a.K));
}

double omega_pinned(int k) { return std::pow(k * kPi / kL, 2) * std::sqrt(kEI / kRhoA); }

}  // namespace

// ---------------------------------------------------------------------------- 1. modal ratios

TEST(BeamDamping, ChenRussellGivesEveryPinnedModeTheRatioZeta) {
  // 120 elements: 15 per half-wave of mode 8. The conforming FE frequencies lie above the
  // continuum's by O((βh)⁴) (mode 8: 2.1e-5 at 60 elements, 1.3e-6 at 120), and the ratio
  // d β_k²/(2ρA ω_k) below ζ by the same relative amount.
  const double zeta = 0.02;
  const auto modes = fe_damped_modes(120, zeta, 0.0);
  ASSERT_GE(modes.size(), 8u);
  std::printf("  %4s %14s %14s %12s %12s %12s\n", "mode", "omega_d FE", "closed form", "zeta FE", "rel. error",
              "omega rel.");
  for (int k = 1; k <= 8; ++k) {
    const DampedMode& m = modes[static_cast<std::size_t>(k - 1)];
    const double wd = omega_pinned(k) * std::sqrt(1.0 - zeta * zeta);
    const double ez = m.zeta / zeta - 1.0, ew = m.omega_d / wd - 1.0;
    std::printf("  %4d %14.8f %14.8f %12.9f %12.3e %12.3e\n", k, m.omega_d, wd, m.zeta, ez, ew);
    EXPECT_LT(std::abs(ez), 1e-3) << "mode " << k;
    EXPECT_LT(std::abs(ew), 1e-5) << "mode " << k;
    EXPECT_NEAR(m.omega, m.omega_d / std::sqrt(1.0 - m.zeta * m.zeta), 1e-9 * m.omega) << "mode " << k;
  }
}

TEST(BeamDamping, KelvinVoigtRatioGrowsWithFrequency) {
  // (c_kv w_sst)_ss on sin(βs): damping rate c_kv β⁴/ρA = 2 ζ_k ω_k with ζ_k = c_kv ω_k/(2 EI);
  // the two laws add. c_kv of the paper's Case II (ζ_old = 0.1 in c_kv = 2ζ_old√(ρA·EI)).
  const double zeta = 0.01, c_kv = 2.0 * 0.1 * std::sqrt(kRhoA * kEI);
  const auto modes = fe_damped_modes(60, zeta, c_kv);
  std::printf("  %4s %12s %12s %12s\n", "mode", "zeta FE", "expected", "rel. error");
  int checked = 0;
  for (int k = 1; checked < 4; ++k) {
    const double expect = zeta + c_kv * omega_pinned(k) / (2.0 * kEI);
    if (expect >= 1.0) break;
    const DampedMode& m = modes[static_cast<std::size_t>(k - 1)];
    std::printf("  %4d %12.9f %12.9f %12.3e\n", k, m.zeta, expect, m.zeta / expect - 1.0);
    EXPECT_LT(std::abs(m.zeta / expect - 1.0), 1e-4) << "mode " << k;
    ++checked;
  }
  EXPECT_EQ(checked, 4);
}

TEST(BeamDamping, DampedModesHandleOverdampingAndRigidBodies) {
  // One DOF: m ü + c u̇ + k u = 0 with c = 3√(mk) (ζ = 1.5): two real roots, each an entry with
  // ζ = 1, their product ω².
  MatrixXd M(1, 1), D(1, 1), K(1, 1);
  M << 2.0;
  K << 8.0;
  D << 3.0 * std::sqrt(16.0);
  const auto r = damped_modes(M, D, K);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_DOUBLE_EQ(r[0].zeta, 1.0);
  EXPECT_DOUBLE_EQ(r[1].zeta, 1.0);
  EXPECT_NEAR(r[0].omega * r[1].omega, 4.0, 1e-12);
  // A free–free beam: the two rigid-body motions are left out, the flexible modes kept.
  io::BeamSpec b = pinned_beam();
  b.left = b.right = io::EndCondition::Free;
  const BeamFE fe = build_beam(b, 20, 1, {}, {});
  const AssembledModel a = assemble(fe.model, beam_coefficients(fe, kRhoA, {kEI}, 0.0, 1.0));
  const auto f = damped_modes(MatrixXd(a.M), MatrixXd(a.D), MatrixXd(a.K));
  ASSERT_FALSE(f.empty());
  // First free–free flexural mode: β L = 4.730040745.
  EXPECT_NEAR(f[0].omega / (std::pow(4.730040745 / kL, 2) * std::sqrt(kEI / kRhoA)), 1.0, 1e-5);
  // A non-symmetric K (as from a numerical linearisation) takes the general path A = [0 I; −M⁻¹K −M⁻¹D]:
  // eigenvalues 4 and 9 of M⁻¹K, undamped, give ω = 2 and 3.
  MatrixXd M2 = MatrixXd::Identity(2, 2), D2 = MatrixXd::Zero(2, 2), K2(2, 2);
  K2 << 4.0, 1.0, 0.0, 9.0;  // eigenvalues 4 and 9
  const auto g = damped_modes(M2, D2, K2);
  ASSERT_EQ(g.size(), 2u);
  EXPECT_NEAR(g[0].omega, 2.0, 1e-12);
  EXPECT_NEAR(g[1].omega, 3.0, 1e-12);
  EXPECT_NEAR(g[0].zeta, 0.0, 1e-12);
}

TEST(BeamDamping, DampedModesKeepALowElasticModeOfAStiffModel) {
  // M = I, K = diag(0, 4, 1e14), D = diag(0, 0.2, 0.2): a rigid-body motion, an elastic mode at
  // ω = 2 (ζ = 0.2/(2·2) = 0.05) and one at 1e7. The elastic mode lies under 1e-6 ω_max = 10, as a
  // fine mesh's fundamental does; the rigid-body floor (rigid_floor, 1e-4 √(1e-6·1e14) = 1) keeps it
  // and leaves out the rigid-body roots.
  const MatrixXd M = MatrixXd::Identity(3, 3);
  const MatrixXd K = VectorXd((VectorXd(3) << 0.0, 4.0, 1e14).finished()).asDiagonal();
  const MatrixXd D = VectorXd((VectorXd(3) << 0.0, 0.2, 0.2).finished()).asDiagonal();
  EXPECT_DOUBLE_EQ(rigid_floor(M.sparseView(), K.sparseView()), 1.0);
  const auto r = damped_modes(M, D, K);
  ASSERT_EQ(r.size(), 2u);
  // The shifted problem gives ω² to ε σ ≈ 2e-8 absolute (modal.h): ω = 2 to about 5e-9.
  EXPECT_NEAR(r[0].omega, 2.0, 1e-7);
  EXPECT_NEAR(r[0].zeta, 0.05, 1e-7);
  EXPECT_NEAR(r[0].omega_d, 2.0 * std::sqrt(1.0 - 0.05 * 0.05), 1e-7);
  EXPECT_NEAR(r[1].omega / 1e7, 1.0, 1e-12);
}

// ------------------------------------------------------------------ 2. the slope-product matrix

TEST(BeamDamping, SlopeProductElementMatrixHasItsClosedForm) {
  for (double h : {0.25, 1.0, 3.7}) {
    hermite::Mat4 closed;
    closed << 36, 3 * h, -36, 3 * h,  //
        3 * h, 4 * h * h, -3 * h, -h * h,  //
        -36, -3 * h, 36, -3 * h,  //
        3 * h, -h * h, -3 * h, 4 * h * h;
    closed /= 30.0 * h;
    const hermite::Mat4 g = hermite::slope_product(h, 0.0, h);
    EXPECT_LT((g - closed).cwiseAbs().maxCoeff(), 1e-13 * closed.cwiseAbs().maxCoeff()) << "h = " << h;
    // Split at an interior point (a section boundary inside the element): the pieces add up.
    const hermite::Mat4 split = hermite::slope_product(h, 0.0, 0.3 * h) + hermite::slope_product(h, 0.3 * h, h);
    EXPECT_LT((split - closed).cwiseAbs().maxCoeff(), 1e-13 * closed.cwiseAbs().maxCoeff()) << "h = " << h;
    // Independent quadrature of the Hermite slopes (composite Simpson, 2000 panels; the integrand
    // is a quartic, so Simpson's error is h⁴-small and the rule is near exact).
    hermite::Mat4 simpson = hermite::Mat4::Zero();
    const int N = 2000;
    for (int i = 0; i <= N; ++i) {
      const double x = static_cast<double>(i) / N, w = (i == 0 || i == N) ? 1.0 : (i % 2 ? 4.0 : 2.0);
      const hermite::Vec4 d = hermite::slope(x, h);
      simpson += w * d * d.transpose();
    }
    simpson *= h / (3.0 * N);
    EXPECT_LT((simpson - closed).cwiseAbs().maxCoeff(), 1e-10 * closed.cwiseAbs().maxCoeff()) << "h = " << h;
  }
}

TEST(BeamDamping, AssembledSlopeMatrixIntegratesTheSlopeSquared) {
  // uᵀ G u for the nodal Hermite interpolant of w = sin(kπs/L) against ∫ w′² ds = (kπ/L)² L/2:
  // the interpolant's slope error is O(h³) and vanishes in the mean, the energy error O(h⁴).
  const int k = 3;
  const double beta = k * kPi / kL, exact = beta * beta * kL / 2.0;
  std::vector<double> err;
  for (int ne : {10, 20, 40}) {
    const BeamFE fe = build_beam(pinned_beam(), ne, 1, {}, {});
    const SparseMatrix* G = nullptr;
    for (const auto& t : fe.model.damping)
      if (t.coefficient == fe.coef_chen_russell(0)) G = &t.matrix;
    ASSERT_NE(G, nullptr);
    VectorXd u(fe.model.ndof);
    for (int node = 0; node <= ne; ++node) {
      const double s = node * kL / ne;
      const int rw = fe.full_to_reduced[static_cast<std::size_t>(2 * node)];
      const int rt = fe.full_to_reduced[static_cast<std::size_t>(2 * node + 1)];
      if (rw >= 0) u[rw] = std::sin(beta * s);
      if (rt >= 0) u[rt] = beta * std::cos(beta * s);
    }
    err.push_back(std::abs(u.dot(*G * u) / exact - 1.0));
    std::printf("  %3d elements: uᵀGu / ∫w′² − 1 = %.3e\n", ne, err.back());
  }
  EXPECT_LT(err.back(), 1e-5);
  for (std::size_t i = 1; i < err.size(); ++i) EXPECT_GT(err[i - 1] / err[i], 12.0) << "halving " << i;
}

// --------------------------------------------------------------------------------- 3. input

TEST(BeamDamping, NegativeZetaOrKelvinVoigtIsRefused) {
  const auto error_of = [](const std::string& yaml) -> std::string {
    try {
      io::parse_scenario(yaml, "scenario 'x.yaml'");
    } catch (const io::InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error_of("beam: {zeta: -0.1}"), "scenario 'x.yaml': beam.zeta must be >= 0, got -0.1");
  EXPECT_EQ(error_of("beam: {c_kv: -1}"), "scenario 'x.yaml': beam.c_kv must be >= 0, got -1");
  EXPECT_EQ(error_of("name: m\ntruth: {overrides: {beam: {c_kv: -2}}}\n"),
            "scenario 'x.yaml': truth.overrides.beam.c_kv must be >= 0, got -2");
  const io::Scenario ok = io::parse_scenario("beam: {zeta: 0.02, c_kv: 3.5}", "x");
  EXPECT_EQ(ok.beam.zeta, 0.02);
  EXPECT_EQ(ok.beam.c_kv, 3.5);
}
