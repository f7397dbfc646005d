#include "scoleid/io/signal.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>

using scoleid::io::Signal;
using scoleid::io::SignalTerm;
using scoleid::io::cubic_table_gain_error;
using scoleid::io::cubic_table_error;

namespace {
// A signal of one term: `type` and `amplitude`, its other fields as `set` leaves them.
template <class Set>
Signal one_term(SignalTerm::Type type, double amplitude, Set set) {
  SignalTerm t;
  t.type = type;
  t.amplitude = amplitude;
  set(t);
  return Signal({t});
}
}  // namespace

TEST(Signal, StepIsZeroBeforeAndAmplitudeFromT0) {
  const Signal s = Signal::step(10.0, 1.5);
  EXPECT_EQ(s(1.4999), 0.0);
  EXPECT_EQ(s(1.5), 10.0);
  EXPECT_EQ(s(100.0), 10.0);
  ASSERT_EQ(s.breakpoints().size(), 1u);
  EXPECT_EQ(s.breakpoints()[0], 1.5);
}

TEST(Signal, BangBangHasZeroImpulseAndThreeBreakpoints) {
  const Signal s = one_term(SignalTerm::Type::BangBang, 3.0, [](SignalTerm& t) {
    t.t0 = 1.0;
    t.width = 2.0;
  });
  double impulse = 0.0;
  const int n = 40000;
  for (int i = 0; i < n; ++i) impulse += s(0.5 + 3.0 * (i + 0.5) / n) * 3.0 / n;
  EXPECT_NEAR(impulse, 0.0, 1e-9);
  EXPECT_EQ(s(1.5), 3.0);
  EXPECT_EQ(s(2.5), -3.0);
  EXPECT_EQ(s.breakpoints(), (std::vector<double>{1.0, 2.0, 3.0}));
}

TEST(Signal, ChirpInstantaneousFrequencySweepsLinearly) {
  const Signal s = one_term(SignalTerm::Type::Chirp, 1.0, [](SignalTerm& t) {
    t.f0 = 1.0;
    t.f1 = 5.0;
    t.duration = 4.0;
  });
  // phase(τ) = 2π(f0 τ + (f1-f0) τ²/(2D)); at τ = D the phase is 2π (f0 + f1) D / 2 = 2π·12.
  EXPECT_NEAR(s(4.0 - 1e-12), std::sin(2.0 * M_PI * 12.0), 1e-9);
  EXPECT_EQ(s(4.0), 0.0);
}

TEST(Signal, TableInterpolatesLinearlyAndHoldsEnds) {
  const Signal s = Signal::table({0.0, 1.0, 3.0}, {0.0, 2.0, -2.0});
  EXPECT_DOUBLE_EQ(s(0.5), 1.0);
  EXPECT_DOUBLE_EQ(s(2.0), 0.0);
  EXPECT_DOUBLE_EQ(s(10.0), -2.0);
  EXPECT_DOUBLE_EQ(s(-1.0), 0.0);
}

TEST(Signal, HaversineIntegratesToHalfAmplitudeTimesWidth) {
  const Signal s = one_term(SignalTerm::Type::Haversine, 4.0, [](SignalTerm& t) { t.width = 0.5; });
  double integral = 0.0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) integral += s((i + 0.5) * 0.5 / n) * 0.5 / n;
  EXPECT_NEAR(integral, 0.5 * 4.0 * 0.5, 1e-9);
}

// A cubic-table's gain and error at x = f·Δt against the table itself: sample cos and sin of x
// cycles per sample, read each table densely between samples, project on the same exponential
// (the gain, G(x)) and take the reading's RMS difference from it (the error, E(x); signal.h).
TEST(Signal, CubicTableErrorsAreTheTablesOwn) {
  for (double x : {0.05, 0.104, 0.146, 0.23, 0.3}) {
    const int n = 400;
    std::vector<double> t(n), c(n), s(n);
    for (int k = 0; k < n; ++k) {
      t[static_cast<std::size_t>(k)] = k;
      c[static_cast<std::size_t>(k)] = std::cos(2 * M_PI * x * k);
      s[static_cast<std::size_t>(k)] = std::sin(2 * M_PI * x * k);
    }
    const Signal fc = Signal::cubic_table(t, c), fs = Signal::cubic_table(t, s);
    std::complex<double> g = 0.0;
    const int m = 64, from = 10, to = 390;  // away from the ends, where the stencil shifts
    for (int k = from * m; k < to * m; ++k) {
      const double tt = (k + 0.5) / m;
      g += std::complex<double>(fc(tt), fs(tt)) * std::exp(std::complex<double>(0.0, -2 * M_PI * x * tt));
    }
    g /= static_cast<double>((to - from) * m);
    // the whole error: relative RMS of the reading against the exponential itself
    double e2 = 0.0;
    for (int k = from * m; k < to * m; ++k) {
      const double tt = (k + 0.5) / m;
      e2 += std::norm(std::complex<double>(fc(tt), fs(tt)) - std::exp(std::complex<double>(0.0, 2 * M_PI * x * tt)));
    }
    const double e = std::sqrt(e2 / static_cast<double>((to - from) * m));
    std::printf("  x = %.3f: table gain %.6f, G(x) %.6f; table error %.6f, E(x) %.6f\n", x, std::abs(g - 1.0),
                cubic_table_gain_error(x), e, cubic_table_error(x));
    EXPECT_NEAR(std::abs(g - 1.0), cubic_table_gain_error(x), 2e-4) << x;
    EXPECT_NEAR(e, cubic_table_error(x), 2e-4 + 1e-3 * e) << x;
  }
  // the values the automatic band's limits are read from (docs/data.md §2.4)
  EXPECT_NEAR(cubic_table_error(0.0996), 0.0025, 2e-5);
  EXPECT_NEAR(cubic_table_error(0.119), 0.005, 5e-5);
  EXPECT_NEAR(cubic_table_gain_error(0.23), 0.054, 1e-3);
}

TEST(Signal, MultisineIsItsLinesWithSchroederPhasesAndTheStatedRms) {
  SignalTerm s;
  s.type = SignalTerm::Type::Multisine;
  s.amplitude = 0.5;  // RMS
  s.width = 2.0;      // period
  s.f0 = 1.2;
  s.f1 = 7.0;
  s.t0 = 0.3;
  const Signal sig({s});
  // lines k/T in [f0, f1]: k = 3 … 14
  bool only = false;
  const auto lines = sig.lines(&only);
  ASSERT_EQ(lines.size(), 12u);
  EXPECT_TRUE(only);
  EXPECT_DOUBLE_EQ(lines.front(), 1.5);
  EXPECT_DOUBLE_EQ(lines.back(), 7.0);
  const double K = 12.0, a = 0.5 * std::sqrt(2.0 / K);
  double ms = 0.0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const double t = 0.3 + 2.0 * i / n + 10.0;  // a period, five periods on
    double direct = 0.0;
    for (int k = 3; k <= 14; ++k) {
      const double rank = k - 2.0;
      direct += a * std::cos(2.0 * M_PI * k * (t - 0.3) / 2.0 - M_PI * rank * (rank - 1.0) / K);
    }
    EXPECT_NEAR(sig(t), direct, 1e-12);
    ms += sig(t) * sig(t) / n;
  }
  EXPECT_NEAR(std::sqrt(ms), 0.5, 1e-12);
  EXPECT_EQ(sig(0.2999), 0.0);  // before t0
  EXPECT_NEAR(sig.highest_frequency(), 7.0, 0.0);
}
