// Eq. 25's quadrature as pattern sums (coefficient_quadrature.h) against the direct sum over every
// term's nonzeros: a banded interior, couplings far outside the band (a rigid body's rows and
// columns), overlapping terms, a constant term, every kind, with and without rate sensors, and the
// coefficients a parameterisation does not read left alone.
#include <gtest/gtest.h>

#include <random>

#include "scoleid/identify/inverse/coefficient_quadrature.h"

using namespace scoleid::identify;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

// A term on coefficient `coef` coupling dofs [first, first + 4) (an element's block) and, when
// `border`, dof n − 1 to every one of them.
OperatorTerm element_term(int n, int first, int coef, bool border, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> trips;
  for (int r = first; r < first + 4; ++r)
    for (int s = first; s < first + 4; ++s) trips.emplace_back(r, s, u(rng));
  if (border)
    for (int r = first; r < first + 4; ++r) {
      trips.emplace_back(r, n - 1, u(rng));
      trips.emplace_back(n - 1, r, u(rng));
    }
  OperatorTerm t;
  t.matrix.resize(n, n);
  t.matrix.setFromTriplets(trips.begin(), trips.end());
  t.coefficient = coef;
  return t;
}

struct Point {
  double wt;
  VectorXd p, pd, x, v, a;
};

// Σ_points wt · leftᵀ T right over every carried term, the mass term by parts without rates.
VectorXd direct(const StructuralModel& m, const std::vector<Point>& pts, bool rates, const std::vector<bool>& needed) {
  VectorXd gc = VectorXd::Zero(m.ncoef);
  auto add = [&](const std::vector<OperatorTerm>& terms, int kind) {
    for (const auto& t : terms) {
      if (t.coefficient < 0 || (!needed.empty() && !needed[static_cast<std::size_t>(t.coefficient)])) continue;
      for (const auto& q : pts) {
        const bool by_parts = kind == 0 && !rates;
        const VectorXd& left = by_parts ? q.pd : q.p;
        const VectorXd& right = kind == 2 ? q.x : (kind == 0 && rates ? q.a : q.v);
        gc[t.coefficient] += (by_parts ? -q.wt : q.wt) * left.dot(t.matrix * right);
      }
    }
  };
  add(m.mass, 0);
  add(m.damping, 1);
  add(m.stiffness, 2);
  return gc;
}

StructuralModel model_with_border(int n, int ncoef, std::mt19937& rng) {
  StructuralModel m;
  m.ndof = n;
  m.ncoef = ncoef;
  for (int e = 0; e + 4 < n; e += 2) {  // overlapping element blocks, as a beam's nodes share dofs
    const int coef = (e / 2) % (ncoef - 1);
    m.stiffness.push_back(element_term(n, e, coef, false, rng));
    m.mass.push_back(element_term(n, e, ncoef - 1, e % 4 == 0, rng));
    m.damping.push_back(element_term(n, e, coef, e % 6 == 0, rng));
  }
  m.stiffness.push_back(element_term(n, 0, -1, true, rng));  // a constant term: no coefficient
  return m;
}

std::vector<Point> random_points(int n, int count, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Point> pts;
  for (int k = 0; k < count; ++k) {
    auto vec = [&] {
      VectorXd x(n);
      for (int i = 0; i < n; ++i) x[i] = u(rng);
      return x;
    };
    pts.push_back({0.5 + 0.5 * u(rng), vec(), vec(), vec(), vec(), vec()});
  }
  return pts;
}

VectorXd pattern_sums(const StructuralModel& m, const std::vector<Point>& pts, bool rates,
                      const std::vector<bool>& needed, const VectorXd& start) {
  CoefficientQuadrature quad(m, rates, needed);
  for (const auto& q : pts) quad.add(q.wt, q.p, q.pd, q.x, q.v, q.a);
  VectorXd gc = start;
  quad.contract(gc);
  return gc;
}

}  // namespace

TEST(CoefficientQuadrature, PatternSumsEqualTheSumOverEveryTermsNonzeros) {
  std::mt19937 rng(7);
  const int n = 23, ncoef = 6;
  const StructuralModel m = model_with_border(n, ncoef, rng);
  const std::vector<Point> pts = random_points(n, 5, rng);
  for (bool rates : {false, true}) {
    const VectorXd ref = direct(m, pts, rates, {});
    const VectorXd got = pattern_sums(m, pts, rates, {}, VectorXd::Zero(ncoef));
    ASSERT_EQ(got.size(), ncoef);
    EXPECT_GT(ref.cwiseAbs().minCoeff(), 1e-3) << "every coefficient carries a share";
    EXPECT_LT((got - ref).cwiseAbs().maxCoeff(), 1e-12 * ref.cwiseAbs().maxCoeff()) << "rates " << rates;
  }
}

// Symmetric element blocks (and border couplings), one of them off symmetry by a rounding-sized
// amount as assembly leaves it: the kinds are summed over the upper triangle, each pair with its
// mirror, and agree with the direct sum over every nonzero of the terms as they are.
TEST(CoefficientQuadrature, SymmetricTermsSummedOnTheUpperTriangleEqualTheDirectSum) {
  std::mt19937 rng(5);
  const int n = 21, ncoef = 4;
  StructuralModel m = model_with_border(n, ncoef, rng);
  for (auto* terms : {&m.mass, &m.damping, &m.stiffness})
    for (auto& t : *terms) t.matrix = 0.5 * (t.matrix + SparseMatrix(t.matrix.transpose()));
  ASSERT_GT(m.stiffness.front().matrix.coeff(0, 1), -2.0);
  m.stiffness.front().matrix.coeffRef(0, 1) *= 1.0 + 4e-16;
  const std::vector<Point> pts = random_points(n, 4, rng);
  for (bool rates : {false, true}) {
    const VectorXd ref = direct(m, pts, rates, {});
    const VectorXd got = pattern_sums(m, pts, rates, {}, VectorXd::Zero(ncoef));
    EXPECT_GT(ref.cwiseAbs().minCoeff(), 1e-3);
    EXPECT_LT((got - ref).cwiseAbs().maxCoeff(), 1e-12 * ref.cwiseAbs().maxCoeff()) << "rates " << rates;
  }
  // A term off symmetry by more than rounding: that kind is summed over the whole pattern, still exact.
  m.damping.front().matrix.coeffRef(0, 1) += 0.25;
  const VectorXd ref = direct(m, pts, false, {});
  const VectorXd got = pattern_sums(m, pts, false, {}, VectorXd::Zero(ncoef));
  EXPECT_LT((got - ref).cwiseAbs().maxCoeff(), 1e-12 * ref.cwiseAbs().maxCoeff());
}

TEST(CoefficientQuadrature, CoefficientsNotNeededAreLeftAsTheyWere) {
  std::mt19937 rng(11);
  const int n = 17, ncoef = 5;
  const StructuralModel m = model_with_border(n, ncoef, rng);
  const std::vector<Point> pts = random_points(n, 3, rng);
  MatrixXd dcdq = MatrixXd::Zero(ncoef, 2);
  dcdq(1, 0) = 2.0;
  dcdq(ncoef - 1, 1) = -1.0;
  const std::vector<bool> needed = CoefficientQuadrature::needed_coefficients(dcdq);
  ASSERT_EQ(needed, (std::vector<bool>{false, true, false, false, true}));
  const VectorXd start = VectorXd::LinSpaced(ncoef, 10.0, 14.0);
  const VectorXd got = pattern_sums(m, pts, false, needed, start);
  const VectorXd ref = start + direct(m, pts, false, needed);
  for (int j = 0; j < ncoef; ++j) {
    if (needed[static_cast<std::size_t>(j)])
      EXPECT_NEAR(got[j], ref[j], 1e-12 * std::abs(ref[j])) << j;
    else
      EXPECT_EQ(got[j], start[j]) << j;
  }
  // The gradient in q is the same as with every coefficient summed.
  const VectorXd all = pattern_sums(m, pts, false, {}, VectorXd::Zero(ncoef));
  EXPECT_LT((dcdq.transpose() * (got - start) - dcdq.transpose() * all).norm(), 1e-12 * all.norm());
  // Nothing carried: reading nothing and adding nothing.
  CoefficientQuadrature none(m, false, std::vector<bool>(ncoef, false));
  EXPECT_FALSE(none.reads_velocity());
  EXPECT_FALSE(none.reads_multiplier_rate());
}
