// The sparse lowest-modes solver (fe/lowest_modes.h) against the dense solution, the Sturm count
// against the dense spectrum, repeated eigenvalues, rigid-body modes, and a fine cantilever against
// the Euler–Bernoulli frequencies. Any backward-stable eigen solver (dense or sparse) gives ω_k² with
// an absolute error of about ε ω_max², ω_max² ≈ max_i K_ii/M_ii: relative ε ω_max²/ω_k², which on a
// fine beam mesh (ω_max² ∝ N⁴) is far above ε for the lowest modes (docs/theory.md §4.4). The
// tolerances below are that bound; the backward error ‖Kφ − ω²Mφ‖ is ε-small whatever the mesh.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>

#include "scoleid/identify/fe/analytic_beam.h"
#include "scoleid/identify/fe/beam_model.h"
#include "scoleid/identify/fe/lowest_modes.h"
#include "scoleid/identify/fe/modal.h"
#include "scoleid/identify/fe/state_space.h"

using namespace scoleid::identify;
using scoleid::io::BeamSpec;
using scoleid::io::EndCondition;

namespace {
constexpr double L = 10.0, EI = 23000.0, RHOA = 67.0;

AssembledModel beam(EndCondition left, EndCondition right, int ne) {
  BeamSpec b;
  b.length = L;
  b.left = left;
  b.right = right;
  b.rho_A = RHOA;
  b.EI = {EI};
  const BeamFE fe = build_beam(b, ne, 1, {}, {});
  return assemble(fe.model, beam_coefficients(fe, RHOA, {EI}, 0.0));
}

// The rounding bound on ω_k: relative ε ω_max² / (2 ω_k²), ω_max² ≈ max_i K_ii/M_ii, times ten.
double rounding(const AssembledModel& a, double omega) {
  double top = 0.0;
  for (Eigen::Index i = 0; i < a.M.rows(); ++i) top = std::max(top, a.K.coeff(i, i) / a.M.coeff(i, i));
  return 10.0 * 0.5 * 2.220446e-16 * top / (omega * omega);
}

// The backward error of a mode: ‖Kφ − ω²Mφ‖∞ / ((‖K‖∞ + ω² ‖M‖∞) ‖φ‖∞).
double backward_error(const AssembledModel& a, double omega, const VectorXd& phi) {
  auto norm_inf = [](const SparseMatrix& A) {
    VectorXd rows = VectorXd::Zero(A.rows());
    for (int k = 0; k < A.outerSize(); ++k)
      for (SparseMatrix::InnerIterator it(A, k); it; ++it) rows[it.row()] += std::abs(it.value());
    return rows.maxCoeff();
  };
  const double w2 = omega * omega;
  const VectorXd r = a.K * phi - w2 * (a.M * phi);
  return r.cwiseAbs().maxCoeff() / ((norm_inf(a.K) + w2 * norm_inf(a.M)) * phi.cwiseAbs().maxCoeff());
}

// |φ_aᵀ M φ_b| for M-orthonormal vectors: 1 when they are the same mode up to sign.
double overlap(const SparseMatrix& M, const VectorXd& a, const VectorXd& b) { return std::abs(a.dot(M * b)); }

SparseMatrix twice(const SparseMatrix& A) {  // diag(A, A): every eigenvalue doubled
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < A.outerSize(); ++k)
    for (SparseMatrix::InnerIterator it(A, k); it; ++it) {
      t.emplace_back(it.row(), it.col(), it.value());
      t.emplace_back(it.row() + A.rows(), it.col() + A.cols(), it.value());
    }
  SparseMatrix D(2 * A.rows(), 2 * A.cols());
  D.setFromTriplets(t.begin(), t.end());
  return D;
}
}  // namespace

TEST(LowestModes, AgreesWithTheDenseSolutionAndTheSturmCountWithItsSpectrum) {
  const AssembledModel a = beam(EndCondition::Clamped, EndCondition::Free, 200);
  const NaturalModes dense = natural_modes(a.M, a.K);
  // Sturm counts at frequencies between the dense solution's modes.
  for (int k : {0, 1, 5, 17, 60}) {
    const double omega = k == 0 ? 0.5 * dense.omega[0] : std::sqrt(dense.omega[k - 1] * dense.omega[k]);
    EXPECT_EQ(modes_below(a.M, a.K, omega), k) << "at " << omega << " rad/s";
  }
  LowestModesOptions o;
  o.below_omega = std::sqrt(dense.omega[11] * dense.omega[12]);  // twelve modes
  LowestModesSummary s;
  const NaturalModes m = lowest_modes(a.M, a.K, o, &s);
  std::printf("  %d modes, subspace %d, %d iterations, residual %.2e\n", s.wanted, s.subspace, s.iterations, s.residual);
  ASSERT_TRUE(s.converged);
  ASSERT_EQ(m.omega.size(), 12);
  EXPECT_DOUBLE_EQ(m.floor, dense.floor);
  for (Eigen::Index k = 0; k < 12; ++k) {
    const double tol = rounding(a, dense.omega[k]);
    std::printf("  mode %2ld: sparse/dense - 1 = %9.2e (bound %.1e), backward errors %.1e / %.1e\n", static_cast<long>(k + 1),
                m.omega[k] / dense.omega[k] - 1.0, tol, backward_error(a, m.omega[k], m.vectors.col(k)),
                backward_error(a, dense.omega[k], dense.vectors.col(k)));
    EXPECT_NEAR(m.omega[k] / dense.omega[k], 1.0, tol) << "mode " << k + 1;
    EXPECT_LT(backward_error(a, m.omega[k], m.vectors.col(k)), 1e-13) << "mode " << k + 1;
    EXPECT_NEAR(overlap(a.M, m.vectors.col(k), m.vectors.col(k)), 1.0, 1e-12) << "M-normalised, mode " << k + 1;
    EXPECT_NEAR(overlap(a.M, m.vectors.col(k), dense.vectors.col(k)), 1.0, 1e-6) << "mode " << k + 1;
  }
  EXPECT_LT(std::abs(m.vectors.col(0).dot(a.M * m.vectors.col(1))), 1e-10);
}

TEST(LowestModes, FindsEveryCopyOfARepeatedEigenvalue) {
  // Two identical beams side by side (a mast bending in two planes): every frequency twice.
  const AssembledModel a = beam(EndCondition::Pinned, EndCondition::Pinned, 60);
  const SparseMatrix M = twice(a.M), K = twice(a.K);
  const NaturalModes one = natural_modes(a.M, a.K);
  LowestModesOptions o;
  o.below_omega = std::sqrt(one.omega[4] * one.omega[5]);
  const NaturalModes m = lowest_modes(M, K, o);
  ASSERT_EQ(m.omega.size(), 10);
  const AssembledModel both{M, SparseMatrix(), K, {}};
  for (Eigen::Index k = 0; k < 10; ++k) {
    EXPECT_NEAR(m.omega[k] / one.omega[k / 2], 1.0, rounding(a, one.omega[k / 2])) << "mode " << k + 1;
    EXPECT_LT(backward_error(both, m.omega[k], m.vectors.col(k)), 1e-13) << "mode " << k + 1;
  }
  // The two copies of each pair span both beams' modes.
  for (Eigen::Index k = 0; k < 10; k += 2) {
    const MatrixXd P = m.vectors.middleCols(k, 2).transpose() * M * m.vectors.middleCols(k, 2);
    EXPECT_NEAR((P - MatrixXd::Identity(2, 2)).norm(), 0.0, 1e-10) << "pair " << k / 2 + 1;
  }
}

TEST(LowestModes, CountsFlexibleModesAboveTheRigidBodyOnes) {
  const AssembledModel a = beam(EndCondition::Free, EndCondition::Free, 80);
  const NaturalModes dense = natural_modes(a.M, a.K);
  LowestModesOptions o;
  o.flexible = 3;
  const NaturalModes m = lowest_modes(a.M, a.K, o);
  ASSERT_EQ(m.omega.size(), 5);  // translation and rotation, then three flexible modes
  EXPECT_LT(m.omega[0], m.floor);
  EXPECT_LT(m.omega[1], m.floor);
  for (Eigen::Index k = 2; k < 5; ++k) EXPECT_NEAR(m.omega[k] / dense.omega[k], 1.0, rounding(a, dense.omega[k])) << "mode " << k + 1;
}

TEST(LowestModes, AFineCantileverMeetsEulerBernoulliInMillisecondsNotMinutes) {
  // 4000 elements (8000 degrees of freedom): a dense solution would take minutes. The mesh's
  // discretisation error is below 1e-9 for these modes; what is left is the rounding bound, which
  // for the fundamental of so fine a mesh is percents (printed: the error is real, of the same
  // order for a dense solution; a mesh of a few hundred elements is the more accurate one).
  const AssembledModel a = beam(EndCondition::Clamped, EndCondition::Free, 4000);
  const auto bl = analytic::beta_L(analytic::Support::ClampedFree, 6);
  const double scale = std::sqrt(EI / RHOA) / (L * L);
  LowestModesOptions o;
  o.below_omega = 1.01 * bl[5] * bl[5] * scale;  // the sixth mode lies a little below it
  const auto t0 = std::chrono::steady_clock::now();
  LowestModesSummary s;
  const NaturalModes m = lowest_modes(a.M, a.K, o, &s);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("  8000 DOF: %d modes in %.3f s (%d iterations, subspace %d)\n", s.wanted, took, s.iterations, s.subspace);
  ASSERT_EQ(m.omega.size(), 6);
  for (Eigen::Index k = 0; k < 6; ++k) {
    const double exact = bl[static_cast<std::size_t>(k)] * bl[static_cast<std::size_t>(k)] * scale;
    const double tol = rounding(a, exact) + 1e-9;
    std::printf("  mode %ld: %.12g rad/s, Euler-Bernoulli %.12g, relative %9.2e (bound %.1e), backward error %.1e\n",
                static_cast<long>(k + 1), m.omega[k], exact, m.omega[k] / exact - 1.0, tol,
                backward_error(a, m.omega[k], m.vectors.col(k)));
    EXPECT_NEAR(m.omega[k] / exact, 1.0, tol) << "mode " << k + 1;
    EXPECT_LT(backward_error(a, m.omega[k], m.vectors.col(k)), 1e-13) << "mode " << k + 1;
  }
  EXPECT_LT(took, 10.0);
}

TEST(LowestModes, AFineMeshsLowestElasticModesAreNotTakenForRigidBodyModes) {
  // A pinned beam's fundamental lies below 1e-6 of a 500-element mesh's highest frequency, and its
  // two lowest below that of a 1000-element one: the identified model's modes (modal_model, dense
  // below kSparseModesFrom degrees of freedom, sparse above) start with the fundamental all the same.
  const auto bl = analytic::beta_L(analytic::Support::PinnedPinned, 2);
  const double scale = std::sqrt(EI / RHOA) / (L * L);
  for (const int ne : {499, 1000}) {
    BeamSpec b;
    b.length = L;
    b.left = b.right = EndCondition::Pinned;
    b.rho_A = RHOA;
    b.EI = {EI};
    b.zeta = 0.01;
    const BeamFE fe = build_beam(b, ne, 1, {}, {});
    const VectorXd c = beam_coefficients(fe, RHOA, {EI}, 0.01);
    const ModalModel mm = modal_model(fe.model, c, 4);
    const AssembledModel a = assemble(fe.model, c);
    const NaturalModes all = ne < 500 ? natural_modes(a.M, a.K) : NaturalModes{};
    if (ne < 500) {
      EXPECT_LT(all.omega[0], 1e-6 * all.omega[all.omega.size() - 1]) << "the case this guards";
    }
    ASSERT_GE(mm.omega.size(), 2);
    for (Eigen::Index k = 0; k < 2; ++k) {
      const double exact = bl[static_cast<std::size_t>(k)] * bl[static_cast<std::size_t>(k)] * scale;
      std::printf("  %d elements, mode %ld: %.10g rad/s (Euler-Bernoulli %.10g), zeta %.4g\n", ne, static_cast<long>(k + 1),
                  mm.omega[k], exact, mm.zeta[k]);
      EXPECT_NEAR(mm.omega[k] / exact, 1.0, rounding(a, exact) + 1e-9) << ne << " elements, mode " << k + 1;
      EXPECT_TRUE(std::isfinite(mm.zeta[k])) << ne << " elements, mode " << k + 1 << " taken for a rigid-body mode";
    }
  }
}
