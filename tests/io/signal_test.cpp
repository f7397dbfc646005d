#include "scoleid/io/signal.h"

#include <gtest/gtest.h>

#include <cmath>

using scoleid::io::Signal;
using scoleid::io::SignalTerm;

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
