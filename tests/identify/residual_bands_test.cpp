// The residual split by frequency (run/residual_bands.h): the bands laid out by the modes, and the
// powers of sines placed on known bins recovered exactly (Parseval).
#include <gtest/gtest.h>

#include <cmath>

#include "scoleid/identify/run/residual_bands.h"

using namespace scoleid::identify;

namespace {

ModalEstimate mode(int k, double f, double zeta) {
  ModalEstimate m;
  m.mode = k;
  m.frequency_hz = f;
  m.damping_ratio = zeta;
  return m;
}

}  // namespace

// 2 s at 1 kHz (bins every 0.5 Hz). Modes at 10 Hz (ζ 0.01: width max(1.5, 0.5) = 1.5 Hz) and 60 Hz
// (ζ 0.02: width max(1.5, 6) = 6 Hz). The residual: a sine of amplitude a on the 60 Hz bin (at mode 2)
// and one of amplitude b at 30 Hz (between the modes); two sensors, the second reading 1000 times
// the first (another unit), so each band's share is the same relative to each record.
TEST(ResidualBands, SinesOnKnownBinsAreFoundInTheirBandsWithTheirPowers) {
  const int N = 2000;
  const double dt = 1e-3;
  std::vector<double> t(N);
  Eigen::MatrixXd m(N, 2), y(N, 2);
  const double a = 0.3, b = 0.1;
  for (int k = 0; k < N; ++k) {
    t[static_cast<std::size_t>(k)] = k * dt;
    const double s = std::sin(2 * M_PI * 10.0 * k * dt) + 0.5 * std::cos(2 * M_PI * 60.0 * k * dt);
    const double r = a * std::sin(2 * M_PI * 60.0 * k * dt) + b * std::cos(2 * M_PI * 30.0 * k * dt);
    m(k, 0) = s;
    y(k, 0) = s + r;
    m(k, 1) = 1000 * s;
    y(k, 1) = 1000 * (s + r);
  }
  const ResidualBands rb = residual_bands(t, m, y, {mode(2, 60.0, 0.02), mode(1, 10.0, 0.01)});
  ASSERT_TRUE(rb.note.empty()) << rb.note;
  ASSERT_EQ(rb.bands.size(), 5u);
  const char* holds[] = {"below mode 1", "mode 1", "between modes 1 and 2", "mode 2", "above mode 2"};
  for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(rb.bands[i].holds, holds[i]);
  EXPECT_DOUBLE_EQ(rb.bands[1].from_hz, 8.5);
  EXPECT_DOUBLE_EQ(rb.bands[1].to_hz, 11.5);
  EXPECT_DOUBLE_EQ(rb.bands[3].from_hz, 54.0);
  EXPECT_DOUBLE_EQ(rb.bands[3].to_hz, 66.0);
  EXPECT_DOUBLE_EQ(rb.bands[4].to_hz, 500.0);
  // Powers: a²/2 at mode 2, b²/2 between the modes, nothing elsewhere; shares a²/(a²+b²), b²/(a²+b²).
  EXPECT_NEAR(rb.bands[3].rms[0], a / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(rb.bands[2].rms[0], b / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(rb.bands[3].rms[1], 1000 * a / std::sqrt(2.0), 1e-9);
  for (std::size_t i : {0u, 1u, 4u}) EXPECT_LT(rb.bands[i].rms[0], 1e-12) << i;
  EXPECT_NEAR(rb.bands[3].share, a * a / (a * a + b * b), 1e-12);
  EXPECT_NEAR(rb.bands[2].share, b * b / (a * a + b * b), 1e-12);
  EXPECT_NEAR(rb.at_modes, 0.9, 1e-12);
  EXPECT_NE(rb.summary.find("90 % at mode 2 (54-66 Hz)"), std::string::npos) << rb.summary;
  EXPECT_NE(rb.summary.find("miss the record's"), std::string::npos) << rb.summary;
  // A fit the test passes: the split, no reading of it.
  const ResidualBands passed = residual_bands(t, m, y, {mode(2, 60.0, 0.02), mode(1, 10.0, 0.01)}, true);
  EXPECT_EQ(passed.summary.find("miss the record's"), std::string::npos) << passed.summary;
  EXPECT_NE(passed.summary.find("90 % at the modes"), std::string::npos) << passed.summary;
}

// Parseval: the bands' mean squares add up to the residual's, whatever it is (here a chirp, an
// offset and a step; an odd number of samples). Modes closer than their widths share their midpoint.
TEST(ResidualBands, TheBandsPowersAddUpToTheResidualsMeanSquare) {
  const int N = 1001;
  const double dt = 0.002;
  std::vector<double> t(N);
  Eigen::MatrixXd m(N, 1), y(N, 1);
  double ms = 0.0;
  for (int k = 0; k < N; ++k) {
    const double tk = k * dt;
    t[static_cast<std::size_t>(k)] = tk;
    m(k, 0) = std::sin(2 * M_PI * (5 + 20 * tk) * tk);
    const double r = 0.2 + (tk > 1.1 ? 0.3 : 0.0) + 0.05 * std::sin(2 * M_PI * 200 * tk * tk);
    y(k, 0) = m(k, 0) + r;
    ms += r * r / N;
  }
  const ResidualBands rb = residual_bands(t, m, y, {mode(1, 20.0, 0.05), mode(2, 24.0, 0.05), mode(3, 400.0, 0.0)});
  ASSERT_TRUE(rb.note.empty()) << rb.note;
  double sum = 0.0, shares = 0.0;
  for (const auto& b : rb.bands) {
    sum += b.rms[0] * b.rms[0];
    shares += b.share;
  }
  EXPECT_NEAR(sum, ms, 1e-12 * ms);
  EXPECT_NEAR(shares, 1.0, 1e-12);
  // Modes 1 and 2 (widths 5 and 6 Hz) meet at 22 Hz; mode 3 lies above Nyquist (250 Hz) and is left out.
  ASSERT_EQ(rb.bands.size(), 4u);
  EXPECT_EQ(rb.bands[1].holds, "mode 1");
  EXPECT_DOUBLE_EQ(rb.bands[1].to_hz, 22.0);
  EXPECT_DOUBLE_EQ(rb.bands[2].from_hz, 22.0);
  EXPECT_EQ(rb.bands[3].holds, "above mode 2");
  EXPECT_DOUBLE_EQ(rb.bands[3].to_hz, 250.0);
}

// No split without a uniform grid or finite outputs, said in the note.
TEST(ResidualBands, NoSplitOnAnUnevenGridOrNonFiniteOutputs) {
  std::vector<double> t{0, 1, 2, 3, 4, 5, 6, 7.5, 8, 9};
  Eigen::MatrixXd m = Eigen::MatrixXd::Ones(10, 1), y = Eigen::MatrixXd::Zero(10, 1);
  EXPECT_NE(residual_bands(t, m, y, {}).note.find("not uniformly sampled"), std::string::npos);
  t[7] = 7;
  y(3, 0) = NAN;
  EXPECT_NE(residual_bands(t, m, y, {}).note.find("not finite"), std::string::npos);
  y(3, 0) = 0;
  const ResidualBands rb = residual_bands(t, m, y, {});
  ASSERT_EQ(rb.bands.size(), 1u);
  EXPECT_EQ(rb.bands[0].holds, "whole record");
  EXPECT_NEAR(rb.bands[0].rms[0], 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(rb.bands[0].share, 1.0);
}
