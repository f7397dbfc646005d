#include "scoleid/io/time_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace scoleid::io;

namespace {

// n samples of a clock of `rate` Hz from t0, each written with printf format `fmt`.
std::vector<double> written(std::size_t n, double rate, double t0, const char* fmt) {
  std::vector<double> t(n);
  for (std::size_t k = 0; k < n; ++k) {
    char buf[64];
    std::snprintf(buf, sizeof buf, fmt, t0 + static_cast<double>(k) / rate);
    t[k] = std::strtod(buf, nullptr);
  }
  return t;
}

}  // namespace

// The times a DAQ writes: exact, to significant digits, to decimals; a gap is not rounding.
TEST(TimeGrid, AUniformClockIsFoundWithinItsWrittenPrecisionAndAGapIsNot) {
  const auto exact = written(1000, 2048.0, 0.0, "%.17g");
  TimeGrid g = uniform_grid(exact);
  EXPECT_TRUE(g.uniform);
  EXPECT_EQ(g.precision, "full");
  EXPECT_NEAR(g.step * 2048.0, 1.0, 1e-13);

  // 6 significant digits over 100 s at 2048 Hz: rounding up to half of 1e-4 s, a tenth of a step.
  const auto six = written(204800, 2048.0, 0.0, "%.6g");
  g = uniform_grid(six);
  std::printf("  6 digits: precision '%s', step %.15g s, largest shift %.3g s (%.3g steps)\n", g.precision.c_str(), g.step,
              g.max_shift, g.max_shift / g.step);
  EXPECT_TRUE(g.uniform);
  EXPECT_EQ(g.precision, "6 significant digits");
  EXPECT_NEAR(g.step * 2048.0, 1.0, 1e-9);
  EXPECT_GT(g.max_shift / g.step, 0.05);
  const auto grid = g.times(six.size());
  for (std::size_t k = 0; k < grid.size(); k += 997) EXPECT_NEAR(grid[k], static_cast<double>(k) / 2048.0, 1e-9) << k;

  // Fixed decimals (a 3 kHz clock from 0.5 s written with 5 decimals).
  g = uniform_grid(written(3000, 3000.0, 0.5, "%.5f"));
  EXPECT_TRUE(g.uniform);
  EXPECT_EQ(g.precision, "5 decimals");
  EXPECT_NEAR(g.step * 3000.0, 1.0, 1e-6);  // rounding of 1.5 % of a step: the fitted step to a few 1e-7
  EXPECT_NEAR(g.t0, 0.5, 1e-7);

  // A dropped sample: the farthest sample is half a step off the best line, far beyond rounding.
  auto gap = written(2000, 2048.0, 0.0, "%.6g");
  gap.erase(gap.begin() + 1200);
  g = uniform_grid(gap);
  EXPECT_FALSE(g.uniform);
  std::printf("  a dropped sample: worst sample %zu, %.3f steps off\n", g.worst + 1, g.max_shift / g.step);
  EXPECT_GT(g.max_shift / g.step, 0.4);

  // A clock whose jitter is larger than its writing: 7 digits written, 1e-3 of a step of jitter.
  std::vector<double> jittered(1000);
  for (std::size_t k = 0; k < jittered.size(); ++k) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.7g", (static_cast<double>(k) + ((k * 7919) % 13 == 0 ? 1e-2 : 0.0)) / 1000.0);
    jittered[k] = std::strtod(buf, nullptr);
  }
  EXPECT_FALSE(uniform_grid(jittered).uniform);
  // A typo (1e20 for 0.03): one significant digit "explains" it, but no clock is left to recognise.
  EXPECT_FALSE(uniform_grid({0.0, 0.01, 0.02, 1e20}).uniform);
}

TEST(TimeGrid, AStatedRateFixesTheGridOrIsRefused) {
  const auto six = written(4096, 2048.0, 1.0, "%.6g");
  std::string why;
  const auto g = stated_grid(six, 2048.0, &why);
  ASSERT_TRUE(g.has_value());
  EXPECT_EQ(g->t0, six.front());
  EXPECT_NEAR(g->times(six.size()).back(), 1.0 + 4095.0 / 2048.0, 1e-12);
  EXPECT_FALSE(stated_grid(six, 2000.0, &why).has_value());
  std::printf("  2000 Hz stated for a 2048 Hz clock: %s\n", why.c_str());
  EXPECT_NE(why.find("steps off the uniform grid"), std::string::npos);
  EXPECT_NE(why.find("2048 Hz"), std::string::npos);
}
