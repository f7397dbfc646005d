// Ladder step 1: the FE beam against closed-form Euler–Bernoulli results.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scoleid/identify/fe/analytic_beam.h"
#include "scoleid/identify/fe/beam_model.h"
#include "scoleid/identify/fe/modal.h"

using namespace scoleid::identify;
using scoleid::io::BeamSpec;
using scoleid::io::EndCondition;

namespace {
constexpr double L = 10.0, EI = 23000.0, RHOA = 67.0;

BeamFE make(EndCondition left, EndCondition right, int ne, std::vector<scoleid::io::InputSpec> in = {},
            double tip_mass = 0.0, double tip_inertia = 0.0) {
  BeamSpec b;
  b.length = L;
  b.left = left;
  b.right = right;
  b.rho_A = RHOA;
  b.EI = {EI};
  b.tip_mass = tip_mass;
  b.tip_inertia = tip_inertia;
  return build_beam(b, ne, 1, in, {});
}

std::vector<double> fe_omegas(const BeamFE& fe) {
  const VectorXd c = beam_coefficients(fe, RHOA, {EI}, 0.0);
  const auto a = assemble(fe.model, c);
  return natural_frequencies(a.M, a.K);
}

scoleid::io::InputSpec force_at(double s) {
  scoleid::io::InputSpec in;
  in.name = "P";
  in.location = s;
  return in;
}

VectorXd static_solution(const BeamFE& fe) {
  const auto a = assemble(fe.model, beam_coefficients(fe, RHOA, {EI}, 0.0));
  Eigen::SimplicialLDLT<SparseMatrix> ldlt(a.K);
  return ldlt.solve(a.loads.at(0));
}

// Observed convergence rates of the first `modes` flexible frequencies over mesh halvings.
void expect_rate_four(EndCondition l, EndCondition r, analytic::Support sup, int rigid, const char* label) {
  const int modes = 4;
  const auto bl = analytic::beta_L(sup, modes);
  const std::vector<int> meshes = {4, 8, 16, 32};
  std::vector<std::vector<double>> err(meshes.size(), std::vector<double>(modes));
  std::printf("%s: relative frequency error\n   ne", label);
  for (int k = 0; k < modes; ++k) std::printf("        mode %d", k + 1);
  std::printf("\n");
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const auto w = fe_omegas(make(l, r, meshes[m]));
    std::printf("%5d", meshes[m]);
    for (int k = 0; k < modes; ++k) {
      const double exact = analytic::omega(bl[static_cast<std::size_t>(k)], L, EI, RHOA);
      err[m][static_cast<std::size_t>(k)] = (w[static_cast<std::size_t>(rigid + k)] - exact) / exact;
      std::printf("  %12.4e", err[m][static_cast<std::size_t>(k)]);
    }
    std::printf("\n");
  }
  std::printf(" rate");
  for (int k = 0; k < modes; ++k) {
    // rate between the two finest meshes whose errors stay well above rounding
    double rate = 0.0;
    for (std::size_t m = 1; m < meshes.size(); ++m) {
      if (std::abs(err[m][static_cast<std::size_t>(k)]) < 1e-7) break;  // dense eigensolver rounding below
      rate = std::log2(err[m - 1][static_cast<std::size_t>(k)] / err[m][static_cast<std::size_t>(k)]);
    }
    std::printf("  %12.2f", rate);
    EXPECT_NEAR(rate, 4.0, 0.3) << label << " mode " << k + 1;
    // Conforming FE: frequencies converge from above.
    EXPECT_GT(err.back()[static_cast<std::size_t>(k)], -1e-12) << label << " mode " << k + 1;
  }
  std::printf("\n");
  EXPECT_LT(std::abs(err.back()[modes - 1]), 5e-5) << label;  // 4th mode, 32 elements
}
}  // namespace

TEST(HermiteBeam, PinnedPinnedFrequenciesConvergeAtRateFour) {
  expect_rate_four(EndCondition::Pinned, EndCondition::Pinned, analytic::Support::PinnedPinned, 0, "pinned-pinned");
}
TEST(HermiteBeam, CantileverFrequenciesConvergeAtRateFour) {
  expect_rate_four(EndCondition::Clamped, EndCondition::Free, analytic::Support::ClampedFree, 0, "clamped-free");
}
TEST(HermiteBeam, FreeFreeFrequenciesConvergeAtRateFourWithTwoRigidModes) {
  const auto w = fe_omegas(make(EndCondition::Free, EndCondition::Free, 8));
  const double w1 = analytic::omega(analytic::beta_L(analytic::Support::FreeFree, 1)[0], L, EI, RHOA);
  EXPECT_LT(w[0], 1e-6 * w1);
  EXPECT_LT(w[1], 1e-6 * w1);
  expect_rate_four(EndCondition::Free, EndCondition::Free, analytic::Support::FreeFree, 2, "free-free");
}

TEST(HermiteBeam, CantileverWithTipMassAndRotaryInertiaMatchesCharacteristicEquation) {
  const double mt = 0.5 * RHOA * L, Jt = 0.02 * RHOA * L * L * L;
  const auto bl = analytic::beta_L_tip_mass(mt / (RHOA * L), Jt / (RHOA * L * L * L), 4);
  const auto w = fe_omegas(make(EndCondition::Clamped, EndCondition::Free, 40, {}, mt, Jt));
  for (int k = 0; k < 4; ++k) {
    const double exact = analytic::omega(bl[static_cast<std::size_t>(k)], L, EI, RHOA);
    EXPECT_NEAR(w[static_cast<std::size_t>(k)] / exact - 1.0, 0.0, 5e-6) << "mode " << k + 1;
  }
  // Sanity of the reference itself: μ = j = 0 reduces to the plain cantilever.
  const auto b0 = analytic::beta_L_tip_mass(0.0, 0.0, 2);
  EXPECT_NEAR(b0[0], analytic::beta_L(analytic::Support::ClampedFree, 1)[0], 1e-12);
}

TEST(HermiteBeam, StaticDeflectionsAreExactAtNodes) {
  // Hermite cubics reproduce the piecewise-cubic static solution of a uniform beam at the nodes.
  {
    const BeamFE fe = make(EndCondition::Pinned, EndCondition::Pinned, 10, {force_at(3.0)});
    const VectorXd u = static_solution(fe);
    for (double x : {1.0, 3.0, 5.0, 8.0}) {
      const double exact = analytic::ss_static_point_load(x, 3.0, 1.0, L, EI);
      EXPECT_NEAR(fe.displacement_row(x) * u, exact, 1e-12 * std::abs(exact)) << "x = " << x;
    }
  }
  {
    const BeamFE fe = make(EndCondition::Clamped, EndCondition::Free, 7, {force_at(L)});
    const VectorXd u = static_solution(fe);
    const double exact = analytic::cantilever_static_tip_load(L, 1.0, L, EI);
    EXPECT_NEAR(fe.displacement_row(L) * u, exact, 1e-12 * exact);
    EXPECT_NEAR(fe.rotation_row(L) * u, L * L / (2.0 * EI), 1e-12 * L * L / (2.0 * EI));
  }
}

TEST(HermiteBeam, LoadBetweenNodesUsesShapeFunctions) {
  // A load at 3.3 on a 10-element mesh (between nodes) still gives exact nodal deflections.
  const BeamFE fe = make(EndCondition::Pinned, EndCondition::Pinned, 10, {force_at(3.3)});
  const VectorXd u = static_solution(fe);
  for (double x : {2.0, 6.0}) {
    const double exact = analytic::ss_static_point_load(x, 3.3, 1.0, L, EI);
    EXPECT_NEAR(fe.displacement_row(x) * u, exact, 1e-12 * std::abs(exact));
  }
}

TEST(HermiteBeam, SectionsNotAlignedWithMeshAreIntegratedExactly) {
  // EI on 3 sections over a 4-element mesh: section boundaries fall inside elements. For the
  // field w = s(s − L)/2 (unit curvature, exactly representable) the strain energy must be
  // ½ ∫ EI ds = ½ Σ EI_k L/3 exactly.
  BeamSpec b;
  b.length = L;
  b.EI = {20000.0, 50000.0, 30000.0};
  const BeamFE coarse = build_beam(b, 4, 3, {}, {});
  const auto kc = assemble(coarse.model, beam_coefficients(coarse, RHOA, b.EI, 0.0)).K;
  auto quad_field = [&](const BeamFE& fe) {
    VectorXd u = VectorXd::Zero(fe.model.ndof);
    for (int node = 0; node <= fe.elements; ++node) {
      const double s = node * L / fe.elements;
      const int rw = fe.full_to_reduced[static_cast<std::size_t>(2 * node)];
      const int rt = fe.full_to_reduced[static_cast<std::size_t>(2 * node + 1)];
      if (rw >= 0) u[rw] = 0.5 * s * s - 0.5 * s * L;  // pinned at both ends: s(s−L)/2
      if (rt >= 0) u[rt] = s - 0.5 * L;
    }
    return u;
  };
  const VectorXd uc = quad_field(coarse);
  const double energy = 0.5 * uc.dot(kc * uc);
  EXPECT_NEAR(energy, 0.5 * (20000.0 + 50000.0 + 30000.0) * L / 3.0, 1e-9 * energy);
}
