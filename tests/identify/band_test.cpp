// Fitting in a frequency band (identification.band; inverse/band_filter.h, docs/theory.md §6.8):
//  - the filter: |G| = 1/√2 at both edges, ≈ 1 in the pass band, the Butterworth roll-off beyond,
//    and its noise gain Σh² equal to the mean of |G|² over the Nyquist range (Parseval);
//  - the commutation the band rests on: the model driven by the filtered input samples gives, at
//    the sample times, the filtered response to the raw samples — to the integrator's error;
//  - the cost's gradient with the band on: costate and Gauss–Newton against central differences,
//    and the Taylor remainder of order 2;
//  - the band's inputs refused where they mean nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>

#include "scoleid/identify/inverse/band_filter.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/io/error.h"
#include "test_support.h"

using namespace scoleid::identify;

namespace {

std::string strip(const std::string& band, const std::string& extra = "") {
  return R"(name: band-strip
structure: beam
beam: {length: 0.6, left: clamped, right: free, rho_A: 0.4, EI: 30, zeta: 0.01}
inputs:
  - {name: hammer, at: beam, kind: force, location: 0.55, unit: N, signal: {type: haversine, amplitude: 5, t0: 0.002, width: 0.002}}
sensors:
  - {name: acc1, at: beam, kind: acceleration, location: 0.3, unit: m/s^2, noise_std: 0.05}
  - {name: w_tip, at: beam, kind: displacement, location: 0.6, unit: m, noise_std: 1.0e-6}
simulation: {duration: 0.3, sample_interval: 0.0005, seed: 2}
identification: {estimate: [EI, rho_A, zeta], initial: {EI: 27, rho_A: 0.43, zeta: 0.012}, elements: 6)" +
         (band.empty() ? std::string() : ", band: " + band) + extra + "}\n";
}

}  // namespace

TEST(BandFilter, EdgesPassBandRollOffAndNoiseGain) {
  const double dt = 5e-4;
  const BandFilter g(5.0, 300.0, dt);
  EXPECT_NEAR(std::abs(g.response(5.0)), 1.0 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(std::abs(g.response(300.0)), 1.0 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(std::abs(g.response(50.0)), 1.0, 1e-3);
  // Order 8 above f_hi: |G| ≈ 1/√(1 + (f/f_hi)^16) in the pre-warped frequency.
  const auto warped = [&](double f) { return std::tan(M_PI * f * dt) / std::tan(M_PI * 300.0 * dt); };
  EXPECT_NEAR(std::abs(g.response(600.0)), 1.0 / std::sqrt(1.0 + std::pow(warped(600.0), 16)), 1e-6);
  // Σh² = (2/f_s) ∫_0^{f_s/2} |G|² df (Parseval), the integral by the midpoint rule on 200 000 points.
  double integral = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) integral += std::norm(g.response((i + 0.5) * (0.5 / dt) / n)) / n;
  const double gain = g.noise_gain(40000);
  std::printf("  noise gain %.6f, Parseval %.6f (the band's share of the Nyquist range %.4f)\n", gain, integral, 295.0 / 1000.0);
  EXPECT_NEAR(gain, integral, 1e-6);
  EXPECT_THROW(BandFilter(0.0, 1000.0, dt), std::invalid_argument);  // at Nyquist
  EXPECT_THROW(BandFilter(10.0, 5.0, dt), std::invalid_argument);
}

TEST(Band, TheModelDrivenByTheFilteredInputIsTheFilteredResponse) {
  // One problem with the band, one without whose input is the same samples read as the band reads
  // any input (the cubic through them): their outputs at the sample times differ by the filter.
  const double step = 2.5e-5;
  auto banded = test_support::make_case(strip("[5, 300]"), false, step);
  auto raw = test_support::make_case(strip(""), false, step);
  Problem& pb = *banded.p;
  Problem& p0 = *raw.p;
  const auto& t = p0.data.t;
  for (auto& sig : p0.signals) {
    std::vector<double> f(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) f[i] = sig(t[i]);
    sig = scoleid::io::Signal::cubic_table(t, f);
  }
  Objective o0(p0.model(), *p0.params, p0.signals, p0.data, p0.objective_options);
  const VectorXd q = p0.params->truth();
  const MatrixXd y0 = o0.predict(q), yb = banded.obj->predict(q);
  const BandFilter g(5.0, 300.0, t[1] - t[0]);
  for (Eigen::Index k = 0; k < y0.cols(); ++k) {
    std::vector<double> col(static_cast<std::size_t>(y0.rows()));
    for (Eigen::Index i = 0; i < y0.rows(); ++i) col[static_cast<std::size_t>(i)] = y0(i, k);
    const auto filtered = g.apply(col);
    double diff = 0.0, norm = 0.0;
    for (Eigen::Index i = 0; i < y0.rows(); ++i) {
      diff += std::pow(yb(i, k) - filtered[static_cast<std::size_t>(i)], 2);
      norm += std::pow(filtered[static_cast<std::size_t>(i)], 2);
    }
    std::printf("  %s: model on the filtered input against the filtered response, relative RMS %.2e\n",
                p0.data.names[static_cast<std::size_t>(k)].c_str(), std::sqrt(diff / norm));
    EXPECT_LT(std::sqrt(diff / norm), 1e-5);
  }
  // The data went through the same filter, and the noise level became the filtered data's.
  EXPECT_GT(pb.band_gain, 0.1);
  EXPECT_LT(pb.band_gain, 0.5);
  EXPECT_NEAR(pb.noise_std[0], 0.05 * std::sqrt(pb.band_gain), 1e-15);
}

TEST(Band, GradientMatchesDifferencesAndTaylorOrderTwo) {
  auto c = test_support::make_case(strip("[5, 300]"), false, 1e-4);
  const VectorXd q = c.p->params->initial();
  test_support::expect_gradients_match_differences(*c.obj, q);
  const auto R = test_support::taylor_remainders(*c.obj, q, 5);
  // Second order once ε is small: the ratio of successive remainders tends to 4 (at the largest ε
  // the third-order term of this lightly damped record still shows).
  test_support::expect_second_order(R, 3);
}

TEST(Band, MeaninglessBandsAreRefusedWithTheirField) {
  auto refuse = [](const std::string& yaml, const std::string& needle) {
    try {
      auto sc = scoleid::io::parse_scenario(yaml, "band.yaml");
      auto p = make_problem(sc, std::nullopt);
      ADD_FAILURE() << "accepted: " << needle;
    } catch (const scoleid::io::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  refuse(strip("[300, 5]"), "identification.band[1]");
  refuse(strip("[5]"), "identification.band");
  refuse(strip("[5, 1200]"), "Nyquist");
  std::string quiet = strip("[5, 300]");
  quiet.replace(quiet.find(", noise_std: 0.05"), 17, "");
  refuse(quiet, "noise_std");
}

// A DAQ's time column written to 6 significant digits ("0.00146484" for 0.00146484375) is its
// uniform clock: the band accepts it and the times are placed back on the grid. A dropped sample
// is not rounding: refused, naming the sample and data.sample_rate. A stated rate fixes the grid.
TEST(Band, ATimeColumnWrittenCoarselyIsItsClockAndAGapIsNamed) {
  const std::string yaml = strip("[5, 300]");
  auto sc = scoleid::io::parse_scenario(yaml, "band.yaml");
  sc.simulation.sample_interval = 1.0 / 2048.0;
  sc.simulation.duration = 614.0 / 2048.0;  // a whole number of samples: the synthetic record is on its clock
  const auto synthetic = make_problem(sc, std::nullopt);
  const auto& d = synthetic->data;
  scoleid::io::DataTable tab;
  tab.source = "daq.csv";
  tab.names = {"hammer", "acc1", "w_tip"};
  tab.columns.assign(3, {});
  for (std::size_t i = 0; i < d.t.size(); ++i) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", d.t[i]);
    tab.t.push_back(std::strtod(buf, nullptr));
    tab.columns[0].push_back(synthetic->signals[0](d.t[i]));
    for (int k = 0; k < 2; ++k) tab.columns[static_cast<std::size_t>(k + 1)].push_back(d.z(static_cast<Eigen::Index>(i), k));
  }
  double jitter = 0.0;
  for (std::size_t i = 1; i < tab.t.size(); ++i) jitter = std::max(jitter, std::abs(tab.t[i] - tab.t[i - 1] - 1.0 / 2048.0) * 2048.0);
  std::printf("  written to 6 digits: intervals vary by %.2e of a step\n", jitter);
  ASSERT_GT(jitter, 1e-6);  // what the band refused before
  const auto p = make_problem(sc, tab, "daq.csv", nullptr, "");
  EXPECT_TRUE(p->columns.time_regularised);
  EXPECT_EQ(p->columns.time.precision, "6 significant digits");
  // The grid is fitted to the rounded times: far closer to the clock than the times as written.
  EXPECT_NEAR(p->columns.time.step * 2048.0, 1.0, 1e-7);
  double written_error = 0.0, grid_error = 0.0;
  for (std::size_t i = 0; i < p->data.t.size(); ++i) {
    written_error = std::max(written_error, std::abs(tab.t[i] - d.t[i]));
    grid_error = std::max(grid_error, std::abs(p->data.t[i] - d.t[i]));
  }
  std::printf("  largest time error: as written %.3g s, on the fitted grid %.3g s\n", written_error, grid_error);
  EXPECT_LT(grid_error, written_error / 50);
  // A dropped sample.
  auto gap = tab;
  const std::size_t drop = gap.t.size() / 3;
  gap.t.erase(gap.t.begin() + static_cast<std::ptrdiff_t>(drop));
  for (auto& c : gap.columns) c.erase(c.begin() + static_cast<std::ptrdiff_t>(drop));
  try {
    make_problem(sc, gap, "daq.csv", nullptr, "");
    ADD_FAILURE() << "a record with a dropped sample was accepted by the band";
  } catch (const scoleid::io::InputError& e) {
    const std::string m = e.what();
    std::printf("  %s\n", m.c_str());
    EXPECT_NE(m.find("identification.band needs uniformly sampled data, and the times of 'daq.csv' are not"), std::string::npos) << m;
    EXPECT_NE(m.find("state data.sample_rate"), std::string::npos) << m;
  }
  // A stated rate: the right one places the times on its grid; another is refused.
  sc.data.sample_rate = 2048.0;
  const auto stated = make_problem(sc, tab, "daq.csv", nullptr, "");
  for (std::size_t i = 0; i < stated->data.t.size(); ++i) ASSERT_NEAR(stated->data.t[i], d.t[i], 1e-12) << i;
  sc.data.sample_rate = 2000.0;
  try {
    make_problem(sc, tab, "daq.csv", nullptr, "");
    ADD_FAILURE() << "a sample rate the times contradict was accepted";
  } catch (const scoleid::io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("data.sample_rate"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("steps off the uniform grid"), std::string::npos) << e.what();
  }
}
