// Convergence arithmetic (crosscheck/richardson.h) and the MAC (crosscheck/modes.h) on cases with
// known answers.
#include "scoleid/crosscheck/richardson.h"

#include <gtest/gtest.h>

#include <cmath>

#include "scoleid/crosscheck/modes.h"

using namespace scoleid::crosscheck;

TEST(Richardson, RecoversOrderAndLimitOfAPowerLaw) {
  for (double p : {1.0, 2.0, 4.0}) {
    auto f = [&](double n) { return 3.0 + 0.7 * std::pow(n, -p); };
    EXPECT_NEAR(observed_order(f(10), f(20), f(40), 2.0), p, 1e-10);
    // Exact for a pure power law of the assumed order.
    EXPECT_NEAR(richardson(f(20), f(40), 2.0, p), 3.0, 1e-13);
  }
  // A higher-order term: the extrapolation error drops from O(n^-2) to O(n^-4).
  auto g = [](double n) { return 1.0 + 1.0 / (n * n) + 5.0 / (n * n * n * n); };
  // Exactly −4 · 5 / 80⁴ = −4.9e-7, against 1.6e-4 before extrapolation.
  EXPECT_NEAR(richardson(g(40), g(80), 2.0, 2.0) - 1.0, -20.0 / std::pow(80.0, 4), 1e-15);
}

TEST(Richardson, NoOrderWithoutAsymptoticDifferences) {
  EXPECT_TRUE(std::isnan(observed_order(1.0, 1.0, 1.0, 2.0, 1e-12)));   // round-off
  EXPECT_TRUE(std::isnan(observed_order(1.0, 0.5, 0.9, 2.0)));          // sign change: not asymptotic
}

TEST(Mac, OneForParallelZeroForOrthogonalScaleFree) {
  Eigen::MatrixXd A(3, 2), B(3, 2);
  A << 1, 0, 2, 0, 0, 1;
  B << -2, 0, -4, 0, 0, 5;   // the same shapes, scaled and sign-flipped
  const Eigen::MatrixXd m = mac_matrix(A, B);
  EXPECT_NEAR(m(0, 0), 1.0, 1e-15);
  EXPECT_NEAR(m(1, 1), 1.0, 1e-15);
  EXPECT_NEAR(m(0, 1), 0.0, 1e-15);
  EXPECT_NEAR(m(1, 0), 0.0, 1e-15);
  Eigen::MatrixXd C(3, 1);
  C << 1, 1, 0;   // 45 degrees from (1, 0, 0): MAC = cos^2
  Eigen::MatrixXd D(3, 1);
  D << 1, 0, 0;
  EXPECT_NEAR(mac_matrix(C, D)(0, 0), 0.5, 1e-15);
}
