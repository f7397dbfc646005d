// The trust-region Gauss–Newton step (gauss_newton_step.h).
#include <gtest/gtest.h>

#include <cmath>

#include "scoleid/identify/inverse/gauss_newton_step.h"

using namespace scoleid::identify;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {
// H with eigenvalues 4 (well seen) and 1e-8 (barely seen), axes rotated by 30°.
MatrixXd test_matrix() {
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  MatrixXd V(2, 2);
  V << c, -s, s, c;
  return V * VectorXd((VectorXd(2) << 4.0, 1e-8).finished()).asDiagonal() * V.transpose();
}
}  // namespace

TEST(TrustRegionStep, GaussNewtonStepWhenItFits) {
  MatrixXd H(2, 2);
  H << 3.0, 1.0, 1.0, 2.0;
  const VectorXd g = (VectorXd(2) << 0.3, -0.2).finished();
  const TrustRegionStep st = trust_region_step(H, g, 1.0);
  const VectorXd gn = -H.ldlt().solve(g);
  EXPECT_EQ(st.lambda, 0.0);
  EXPECT_FALSE(st.on_boundary);
  EXPECT_LT((st.delta - gn).norm(), 1e-14);
  EXPECT_NEAR(st.predicted, 0.5 * g.dot(H.ldlt().solve(g)), 1e-14);
}

TEST(TrustRegionStep, OnTheBoundaryTheBarelySeenDirectionTakesTheDamping) {
  const MatrixXd H = test_matrix();
  const Eigen::SelfAdjointEigenSolver<MatrixXd> es(H);
  const VectorXd strong = es.eigenvectors().col(1), weak = es.eigenvectors().col(0);
  const VectorXd g = 0.8 * strong + 1e-3 * weak;  // Gauss–Newton step: 0.2 along strong, 1e5 along weak
  const TrustRegionStep st = trust_region_step(H, g, 0.5);
  EXPECT_TRUE(st.on_boundary);
  EXPECT_NEAR(st.delta.norm(), 0.5, 1e-8);
  EXPECT_GT(st.lambda, 0.0);
  EXPECT_GT(st.predicted, 0.0);
  // λ ≈ 2e-3 here: the well-seen component keeps 99.9 % of its Gauss–Newton length.
  EXPECT_NEAR(-st.delta.dot(strong), 0.2, 0.2 * 1e-3);
  // Same g with λ diag H damping would have to shorten both: check the floor does what it says.
  const TrustRegionStep floored = trust_region_step(H, g, 10.0, 0.1);
  EXPECT_NEAR(floored.lambda, 0.1, 1e-12);
  EXPECT_NEAR(-floored.delta.dot(weak), 1e-3 / (1e-8 + 0.1), 1e-9);
}

TEST(TrustRegionStep, RadiusFollowsTheRatioOfActualToPredictedDecrease) {
  TrustRegionStep st;
  st.delta = VectorXd::Constant(1, 0.8);
  st.on_boundary = true;
  EXPECT_DOUBLE_EQ(update_radius(0.8, st, 0.1, 5.0), 0.2);   // poor model: a quarter of the step
  EXPECT_DOUBLE_EQ(update_radius(0.8, st, 0.5, 5.0), 0.8);   // adequate: keep
  EXPECT_DOUBLE_EQ(update_radius(0.8, st, 0.9, 5.0), 1.6);   // good and at the boundary: double
  EXPECT_DOUBLE_EQ(update_radius(4.0, st, 0.9, 5.0), 5.0);   // capped
  st.on_boundary = false;
  EXPECT_DOUBLE_EQ(update_radius(0.8, st, 0.9, 5.0), 0.8);   // inside: the radius did not bind
}
