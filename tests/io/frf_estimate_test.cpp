#include "scoleid/io/frf_estimate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

using namespace scoleid::io;
using cd = std::complex<double>;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<double> white(std::size_t n, unsigned seed, double sigma = 1.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::vector<double> x(n);
  for (double& v : x) v = g(rng);
  return x;
}

// y[n] = a x[n] + b x[n − d] on the samples of x from d on (x before them is the filter's history):
// H(f) = a + b e^{−iωd/fs}.
struct Fir {
  double a, b;
  std::size_t d;
  std::vector<double> apply(const std::vector<double>& x) const {
    std::vector<double> y(x.size() - d);
    for (std::size_t n = 0; n < y.size(); ++n) y[n] = a * x[n + d] + b * x[n];
    return y;
  }
  cd H(double f, double fs) const { return a + b * std::polar(1.0, -2 * kPi * f * double(d) / fs); }
};

// y[n] = 2r cos θ y[n−1] − r² y[n−2] + x[n]: H(f) = 1/(1 − 2r cos θ z⁻¹ + r² z⁻²), z = e^{iω/fs}.
struct Resonator {
  double r, theta;
  std::vector<double> apply(const std::vector<double>& x) const {
    std::vector<double> y(x.size());
    double y1 = 0, y2 = 0;
    for (std::size_t n = 0; n < x.size(); ++n) {
      y[n] = 2 * r * std::cos(theta) * y1 - r * r * y2 + x[n];
      y2 = y1;
      y1 = y[n];
    }
    return y;
  }
  cd H(double f, double fs) const {
    const cd z1 = std::polar(1.0, -2 * kPi * f / fs);
    return 1.0 / (1.0 - 2 * r * std::cos(theta) * z1 + r * r * z1 * z1);
  }
};

std::vector<double> tail(const std::vector<double>& x, std::size_t from) { return {x.begin() + long(from), x.end()}; }

std::vector<double> add(std::vector<double> x, const std::vector<double>& noise) {
  for (std::size_t i = 0; i < x.size(); ++i) x[i] += noise[i];
  return x;
}

FrfData welch(const std::vector<double>& x, const std::vector<std::vector<double>>& ys, const WelchOptions& o) {
  WelchFrf w(int(ys.size()), o);
  std::vector<const double*> p;
  std::vector<std::string> names;
  for (const auto& y : ys) {
    p.push_back(y.data());
    names.push_back("s" + std::to_string(names.size()));
  }
  w.add(x.data(), p, x.size());
  return w.result("test", "force", names);
}

WelchOptions options(double fs, long segment, double overlap, FrfWindow window) {
  WelchOptions o;
  o.sample_rate = fs;
  o.segment = segment;
  o.overlap = overlap;
  o.window = window;
  return o;
}

// The largest |Ĥ − H|/|H| over the lines.
template <class System>
double worst_relative_error(const FrfData& d, const System& sys, double fs) {
  double worst = 0;
  for (int j = 0; j < d.lines(); ++j) {
    const cd h = sys.H(d.f_hz[j], fs);
    worst = std::max(worst, std::abs(d.channels[0].H[j] - h) / std::abs(h));
  }
  return worst;
}

// Mean over lines of |Ĥ − H|²/σ̂² and the ratio of the means of |Ĥ − H|² and σ̂².
template <class System>
void add_calibration(const FrfData& d, const System& sys, double fs, double& ratio_sum, double& err_sum, double& var_sum,
                     int& count) {
  for (int j = 0; j < d.lines(); ++j) {
    const double e = std::norm(d.channels[0].H[j] - sys.H(d.f_hz[j], fs));
    ratio_sum += e / d.channels[0].variance[j];
    err_sum += e;
    var_sum += d.channels[0].variance[j];
    ++count;
  }
}

}  // namespace

// A periodic input (period = the segment) through an FIR in steady state: every segment is a
// circular shift of one period, so with a rectangular window Y_k = H X_k holds exactly at every line
// — for a power-of-two segment (radix 2) and for 1000 samples (Bluestein).
TEST(WelchFrf, H1IsExactForAPeriodicInputWithARectangularWindow) {
  const Fir fir{1.0, -0.6, 3};
  for (long n : {1024L, 1000L}) {
    const std::vector<double> period = white(std::size_t(n), 7);
    std::vector<double> x(std::size_t(9 * n + 3));
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = period[i % std::size_t(n)];
    const FrfData d = welch(tail(x, 3), {fir.apply(x)}, options(2000.0, n, 0.5, FrfWindow::Rectangular));
    const double worst = worst_relative_error(d, fir, 2000.0);
    std::printf("  segment %ld: %d segments, largest |H1 - H|/|H| %.2e\n", n, d.averages, worst);
    EXPECT_EQ(d.averages, 17);
    EXPECT_EQ(d.lines(), int(n / 2));
    EXPECT_DOUBLE_EQ(d.f_hz.front(), 2000.0 / double(n));
    EXPECT_DOUBLE_EQ(d.f_hz.back(), 1000.0);
    EXPECT_LT(worst, 1e-12);
    for (int j = 0; j < d.lines(); ++j) EXPECT_NEAR(d.channels[0].coherence[j], 1.0, 1e-12);
  }
}

// White noise (not periodic): the response to samples before a segment leaks into it. H1 against
// the exact transfer function: the FIR with a rectangular and a Hann window, the resonator
// (r = 0.98, a peak 26 lines wide) with Hann. Measured: 2.9e-2, 2.9e-3 and 9.0e-3 (relative, the
// largest over the lines); the bounds leave a margin.
TEST(WelchFrf, H1MatchesKnownDiscreteSystemsDrivenByWhiteNoise) {
  const double fs = 1000.0;
  const Fir fir{1.0, 0.5, 5};
  const std::vector<double> x = white(1024 * 64 + 5, 11);
  const FrfData rect = welch(tail(x, 5), {fir.apply(x)}, options(fs, 1024, 0.0, FrfWindow::Rectangular));
  const FrfData hann = welch(tail(x, 5), {fir.apply(x)}, options(fs, 1024, 0.5, FrfWindow::Hann));
  const double e_rect = worst_relative_error(rect, fir, fs), e_hann = worst_relative_error(hann, fir, fs);

  const Resonator res{0.98, 2 * kPi * 0.1};
  const std::vector<double> u = white(4096 * 64 + 2000, 12);
  const FrfData iir = welch(tail(u, 2000), {tail(res.apply(u), 2000)}, options(fs, 4096, 0.5, FrfWindow::Hann));
  const double e_iir = worst_relative_error(iir, res, fs);
  std::printf("  largest |H1 - H|/|H|: FIR d=5 rectangular %.2e, Hann 50%% %.2e; resonator Hann 50%% %.2e\n", e_rect, e_hann,
              e_iir);
  EXPECT_LT(e_rect, 0.03);
  EXPECT_LT(e_hann, 5e-3);
  EXPECT_LT(e_iir, 0.02);
  // at the resonance, |H| = 1/((1 − r)·|1 − r e^{−2iθ}|) and the phase near −90°
  const int peak = int(std::lround(100.0 / (fs / 4096)));
  EXPECT_NEAR(std::abs(iir.channels[0].H[peak - 1]) / std::abs(res.H(iir.f_hz[peak - 1], fs)), 1.0, 0.01);
}

// y = H x + n with white output noise: the coherence is |H|²/(|H|² + σ_n²) within its scatter
// (σ(γ̂²) ≈ √2 γ(1 − γ²)/√K), and the variance is calibrated: |Ĥ − H|²/σ̂² averages to 1 over lines
// and seeds, without overlap ((K − 1)/(K − 2) exactly: an F(2, 2K − 2) variable) and for Hann
// segments overlapping by half (where the overlap's correlation c = 1/6 counts).
TEST(WelchFrf, CoherenceAndVarianceAreCalibratedWithOutputNoise) {
  const double fs = 1000.0, sigma_n = 0.5;
  const Fir fir{1.0, 0.5, 1};
  struct Case {
    const char* name;
    WelchOptions o;
    std::size_t samples;
  };
  const Case cases[] = {{"rectangular, no overlap", options(fs, 256, 0.0, FrfWindow::Rectangular), 256 * 64 + 1},
                        {"Hann, 50 % overlap", options(fs, 256, 0.5, FrfWindow::Hann), 128 * 65 + 1}};
  for (const Case& c : cases) {
    double ratio = 0, err = 0, var = 0, coh_bias = 0, coh_z2 = 0;
    int count = 0, segments = 0;
    for (unsigned seed = 0; seed < 64; ++seed) {
      const std::vector<double> x = white(c.samples, 100 + seed);
      const std::vector<double> y = add(fir.apply(x), white(c.samples - 1, 900 + seed, sigma_n));
      const FrfData d = welch(tail(x, 1), {y}, c.o);
      segments = d.averages;
      add_calibration(d, fir, fs, ratio, err, var, count);
      for (int j = 0; j < d.lines(); ++j) {
        const double h2 = std::norm(fir.H(d.f_hz[j], fs)), g2 = h2 / (h2 + sigma_n * sigma_n);
        const double sd = std::sqrt(2.0) * std::sqrt(g2) * (1 - g2) / std::sqrt(double(d.averages));
        coh_bias += d.channels[0].coherence[j] - g2;
        coh_z2 += std::pow((d.channels[0].coherence[j] - g2) / sd, 2);
      }
    }
    const double mean_ratio = ratio / count, f_mean = (segments - 1.0) / (segments - 2.0);
    std::printf("  %s, K = %d: mean |H-H|^2/var %.4f (F-distribution mean %.4f), mean |H-H|^2 / mean var %.4f; "
                "coherence bias %.4f, rms z %.3f (%d lines)\n",
                c.name, segments, mean_ratio, f_mean, err / var, coh_bias / count, std::sqrt(coh_z2 / count), count);
    EXPECT_NEAR(mean_ratio / f_mean, 1.0, 0.1);
    EXPECT_NEAR(err / var, 1.0, 0.05);  // ±1.6 % scatter; F = 1 for the overlapped Hann would read 1.05
    EXPECT_NEAR(coh_bias / count, 0.0, 0.01);
    EXPECT_NEAR(std::sqrt(coh_z2 / count), 1.0, 0.3);
  }
}

// A pure delay τ has H = e^{−iωτ}: the phase falls with frequency (e^{+iωt} time dependence).
TEST(WelchFrf, APureDelayHasPhaseMinusOmegaTau) {
  const double fs = 1000.0;
  const Fir delay{0.0, 1.0, 3};  // y[n] = x[n − 3], τ = 3 ms
  const std::vector<double> x = white(512 * 40 + 3, 21);
  const FrfData d = welch(tail(x, 3), {delay.apply(x)}, options(fs, 512, 0.5, FrfWindow::Hann));
  double worst = 0;
  for (int j = 0; j < d.lines(); ++j) {
    const double w = 2 * kPi * d.f_hz[j];
    worst = std::max(worst, std::abs(std::arg(d.channels[0].H[j] * std::polar(1.0, w * 3e-3))));
  }
  std::printf("  largest |arg(H1 e^{iwt})| %.2e rad over %d lines\n", worst, d.lines());
  EXPECT_LT(worst, 0.01);
  EXPECT_NEAR(std::arg(d.channels[0].H[9]), -2 * kPi * d.f_hz[9] * 3e-3, 0.01);  // −0.37 rad at 19.5 Hz
  EXPECT_LT(std::arg(d.channels[0].H[9]), 0.0);
}

// Chunks of 1, 7 and 1000 samples (two responses: the input and the first response share a complex
// FFT, the second response is alone) give the one-chunk result.
TEST(WelchFrf, StreamingInChunksGivesTheOneChunkResult) {
  const Fir fir{1.0, 0.5, 2};
  const std::vector<double> x = white(300 * 12 + 2, 31);
  const std::vector<double> y1 = fir.apply(x), y2 = add(fir.apply(x), white(y1.size(), 32, 0.3));
  const std::vector<double> xs = tail(x, 2);
  WelchOptions o = options(500.0, 300, 0.3, FrfWindow::Hann);
  const FrfData whole = welch(xs, {y1, y2}, o);
  for (std::size_t chunk : {std::size_t(1), std::size_t(7), std::size_t(1000)}) {
    WelchFrf w(2, o);
    for (std::size_t at = 0; at < xs.size(); at += chunk) {
      const std::size_t n = std::min(chunk, xs.size() - at);
      w.add(xs.data() + at, {y1.data() + at, y2.data() + at}, n);
    }
    const FrfData d = w.result("test", "force", {"s0", "s1"});
    ASSERT_EQ(d.averages, whole.averages);
    ASSERT_EQ(d.lines(), whole.lines());
    for (int s = 0; s < 2; ++s)
      for (int j = 0; j < d.lines(); ++j) {
        EXPECT_NEAR(std::abs(d.channels[s].H[j] - whole.channels[s].H[j]), 0.0, 1e-12 * std::abs(whole.channels[s].H[j]));
        EXPECT_NEAR(d.channels[s].variance[j], whole.channels[s].variance[j], 1e-12 * whole.channels[s].variance[j]);
        EXPECT_NEAR(d.channels[s].coherence[j], whole.channels[s].coherence[j], 1e-12);
      }
  }
  EXPECT_EQ(whole.averages, 16);  // hop 210: 1 + (3600 − 300)/210
}

// Noise on the input only, x = u + m: H1 = H Suu/(Suu + Smm) (here 1/(1 + 0.5²) = 0.8), H2 = H.
TEST(WelchFrf, H2IsUnbiasedWithInputNoiseWhereH1IsLowByTheKnownFactor) {
  const double fs = 1000.0;
  const Fir fir{1.0, 0.5, 1};
  const std::vector<double> u = white(256 * 400 + 1, 41);
  const std::vector<double> y = fir.apply(u), x = add(tail(u, 1), white(y.size(), 42, 0.5));
  WelchOptions o = options(fs, 256, 0.0, FrfWindow::Rectangular);
  const FrfData h1 = welch(x, {y}, o);
  o.estimator = FrfEstimator::H2;
  const FrfData h2 = welch(x, {y}, o);
  EXPECT_EQ(h1.estimator, "H1");
  EXPECT_EQ(h2.estimator, "H2");
  cd r1 = 0, r2 = 0;
  for (int j = 0; j < h1.lines(); ++j) {
    r1 += h1.channels[0].H[j] / fir.H(h1.f_hz[j], fs);
    r2 += h2.channels[0].H[j] / fir.H(h2.f_hz[j], fs);
  }
  r1 /= double(h1.lines());
  r2 /= double(h2.lines());
  std::printf("  mean H1/H %.4f%+.4fi (expected 0.8), mean H2/H %.4f%+.4fi (expected 1)\n", r1.real(), r1.imag(), r2.real(),
              r2.imag());
  EXPECT_NEAR(r1.real(), 0.8, 0.01);
  EXPECT_NEAR(r2.real(), 1.0, 0.01);
  EXPECT_NEAR(r1.imag(), 0.0, 0.01);
  EXPECT_NEAR(r2.imag(), 0.0, 0.01);
}

TEST(WelchFrf, KeepsTheLinesInTheBand) {
  const std::vector<double> x = white(2000, 51);
  WelchOptions o = options(1000.0, 100, 0.5, FrfWindow::Hann);
  o.f_min = 100;
  o.f_max = 200;
  const FrfData d = welch(x, {x}, o);
  ASSERT_EQ(d.lines(), 10);
  EXPECT_DOUBLE_EQ(d.f_hz.front(), 110.0);
  EXPECT_DOUBLE_EQ(d.f_hz.back(), 200.0);
  EXPECT_EQ(d.averages, 39);
  EXPECT_EQ(d.channels[0].sensor, "s0");
  EXPECT_EQ(d.input, "force");
  for (int j = 0; j < d.lines(); ++j) EXPECT_NEAR(std::abs(d.channels[0].H[j] - 1.0), 0.0, 1e-12);
}

namespace {

// Three sines at frequencies off the record's bins plus a constant, through the gains G, with
// white noise on the input and on the response.
struct ThreeLines {
  double fs = 1000.0;
  std::vector<double> f{13.7, 41.3, 97.15}, amp{1.0, 0.7, 0.4}, phase{0.4, -1.1, 2.0};
  std::vector<cd> G{std::polar(2.0, -0.3), std::polar(0.5, 1.2), std::polar(1.5, -2.5)};
  void make(std::size_t n, unsigned seed, double noise, std::vector<double>& x, std::vector<double>& y) const {
    x = noise > 0 ? white(n, seed, noise) : std::vector<double>(n, 0.0);
    y = noise > 0 ? white(n, seed + 5000, noise) : std::vector<double>(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      const double t = double(i) / fs;
      x[i] += 0.3;
      for (std::size_t l = 0; l < f.size(); ++l) {
        x[i] += amp[l] * std::cos(2 * kPi * f[l] * t + phase[l]);
        y[i] += std::abs(G[l]) * amp[l] * std::cos(2 * kPi * f[l] * t + phase[l] + std::arg(G[l]));
      }
    }
  }
  LinesOptions lines() const {
    LinesOptions o;
    o.sample_rate = fs;
    o.lines_hz = f;
    return o;
  }
};

FrfData lines_frf(const std::vector<double>& x, const std::vector<double>& y, const LinesOptions& o) {
  return harmonic_frf(x.data(), {y.data()}, x.size(), o, "test", "force", {"s0"});
}

}  // namespace

TEST(HarmonicFrf, RecoversGainAndPhaseAtLinesOffTheBins) {
  const ThreeLines s;
  std::vector<double> x, y;
  s.make(9973, 1, 0.05, x, y);
  const FrfData d = lines_frf(x, y, s.lines());
  EXPECT_EQ(d.estimator, "lines");
  EXPECT_EQ(d.averages, 136);  // 13.7 Hz over 9.973 s: 136.6 periods
  ASSERT_EQ(d.lines(), 3);
  EXPECT_TRUE(d.channels[0].coherence.empty());
  for (int l = 0; l < 3; ++l) {
    const cd h = d.channels[0].H[l];
    const double sd = std::sqrt(d.channels[0].variance[l]);
    std::printf("  %.2f Hz: |H| %.5f (true %.5f), phase %.5f (true %.5f) rad, sigma %.2e\n", d.f_hz[l], std::abs(h),
                std::abs(s.G[l]), std::arg(h), std::arg(s.G[l]), sd);
    EXPECT_LT(std::abs(h - s.G[l]), 5 * sd);
    EXPECT_NEAR(sd, std::sqrt(4 * 0.05 * 0.05 / 9973 * (1 + std::norm(s.G[l]))) / s.amp[l], 0.1 * sd);
  }
}

// Over seeds, |Ĥ − H|²/σ̂² averages to 1 (3 lines × 400 records).
TEST(HarmonicFrf, VarianceIsCalibratedOverSeeds) {
  const ThreeLines s;
  double ratio = 0;
  int count = 0;
  std::vector<double> x, y;
  for (unsigned seed = 0; seed < 400; ++seed) {
    s.make(4001, 10 + seed, 0.2, x, y);
    const FrfData d = lines_frf(x, y, s.lines());
    for (int l = 0; l < 3; ++l, ++count) ratio += std::norm(d.channels[0].H[l] - s.G[l]) / d.channels[0].variance[l];
  }
  std::printf("  mean |H-H|^2/var over %d lines: %.4f\n", count, ratio / count);
  EXPECT_NEAR(ratio / count, 1.0, 0.1);
}

// Whole periods of every line: the DFT shortcut and the general least squares agree.
TEST(HarmonicFrf, TheWholePeriodShortcutEqualsTheGeneralFit) {
  ThreeLines s;
  s.f = {10.0, 37.0, 123.4};  // over 10 s: 100, 370 and 1234 cycles
  std::vector<double> x, y;
  s.make(10000, 3, 0.05, x, y);
  LinesOptions o = s.lines();
  const FrfData fast = lines_frf(x, y, o);
  o.dft_when_orthogonal = false;
  const FrfData general = lines_frf(x, y, o);
  double worst = 0, worst_var = 0;
  for (int l = 0; l < 3; ++l) {
    worst = std::max(worst, std::abs(fast.channels[0].H[l] - general.channels[0].H[l]) / std::abs(general.channels[0].H[l]));
    worst_var = std::max(worst_var, std::abs(fast.channels[0].variance[l] / general.channels[0].variance[l] - 1));
    EXPECT_LT(std::abs(fast.channels[0].H[l] - s.G[l]), 5 * std::sqrt(fast.channels[0].variance[l]));
  }
  std::printf("  shortcut vs general: H %.2e, variance %.2e (relative)\n", worst, worst_var);
  EXPECT_LT(worst, 1e-10);
  EXPECT_LT(worst_var, 1e-10);
  EXPECT_EQ(fast.averages, 100);
}

namespace {

template <class F>
void expect_refused(F&& f, const std::string& words) {
  try {
    f();
    ADD_FAILURE() << "not refused (" << words << ")";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(WelchFrf, RefusesBadArguments) {
  auto make = [](WelchOptions o) { WelchFrf w(1, o); };
  const WelchOptions good = options(1000.0, 64, 0.5, FrfWindow::Hann);
  WelchOptions o = good;
  o.sample_rate = 0;
  expect_refused([&] { make(o); }, "sample rate must be positive, got 0");
  o = good;
  o.segment = 1;
  expect_refused([&] { make(o); }, "segment must hold at least 2 samples, got 1");
  o = good;
  o.overlap = 1.0;
  expect_refused([&] { make(o); }, "overlap must be in [0, 1), got 1");
  o.overlap = -0.1;
  expect_refused([&] { make(o); }, "overlap must be in [0, 1), got -0.1");
  o = good;
  o.f_max = 600;
  expect_refused([&] { make(o); }, "f_max must be in (f_min, 500 Hz], got 600");
  o = good;
  o.f_min = 100;
  o.f_max = 105;  // lines every 15.625 Hz: 93.75, 109.375
  expect_refused([&] { make(o); }, "no line");
  expect_refused([&] { WelchFrf w(0, good); }, "at least one response");

  const std::vector<double> x = white(100, 1);
  std::vector<double> bad = x;
  bad[42] = std::nan("");
  WelchFrf w(1, good);
  expect_refused([&] { w.add(x.data(), {bad.data()}, bad.size()); }, "sample 42 of response 0 is not finite");
  expect_refused([&] { w.add(x.data(), {x.data(), x.data()}, x.size()); }, "2 response channels fed, 1 expected");
  w.add(x.data(), {x.data()}, 63);  // a segment longer than the record
  expect_refused([&] { w.result("t", "f", {"s"}); }, "needs at least 2 segments");
  w.add(x.data(), {x.data()}, 33);  // 96 samples: segments at 0 and 32
  EXPECT_EQ(w.segments(), 2);
  expect_refused([&] { w.result("t", "f", {"s", "t"}); }, "2 response names for 1 responses");
  EXPECT_NO_THROW(w.result("t", "f", {"s"}));
}

TEST(HarmonicFrf, RefusesBadArguments) {
  const ThreeLines s;
  std::vector<double> x, y;
  s.make(2000, 1, 0.0, x, y);  // no noise: a line the input lacks is zero to rounding
  LinesOptions o = s.lines();
  o.sample_rate = -1;
  expect_refused([&] { lines_frf(x, y, o); }, "sample rate must be positive, got -1");
  o = s.lines();
  o.lines_hz = {0.0, 10.0};
  expect_refused([&] { lines_frf(x, y, o); }, "line 0 Hz is outside (0, 500 Hz)");
  o.lines_hz = {10.0, 500.0};
  expect_refused([&] { lines_frf(x, y, o); }, "line 500 Hz is outside (0, 500 Hz)");
  o.lines_hz = {20.0, 10.0};
  expect_refused([&] { lines_frf(x, y, o); }, "strictly increasing");
  o.lines_hz = {13.7, 13.700001};  // 1e-6 Hz apart in a 2 s record
  expect_refused([&] { lines_frf(x, y, o); }, "cannot be told apart");
  o = s.lines();
  o.lines_hz.push_back(200.0);  // no input there
  expect_refused([&] { lines_frf(x, y, o); }, "the input has no line at 200 Hz");
  o = s.lines();
  std::vector<double> bad = y;
  bad[7] = INFINITY;
  expect_refused([&] { lines_frf(x, bad, o); }, "sample 7 of response 0 is not finite");
  expect_refused([&] { harmonic_frf(x.data(), {y.data()}, 7, o, "t", "f", {"s"}); }, "3 lines need more than 7 samples");
}

// Impact: a burst from rest through a resonator, the record long enough for the windowed response
// to die out: the windowed DFTs' ratio is the resonator's transfer function at z = e^{(a + iω)/fs}
// (frf_estimate.h 3), to the truncation e^{−aT}; the variance is σ_y² Σw²/|X|².
TEST(ImpactFrf, TheWindowedRatioIsTheTransferFunctionAtAComplexFrequency) {
  const double fs = 1000, r = 0.9995, theta = 2 * kPi * 50 / fs;
  const std::size_t n = 4000;
  std::vector<double> x = white(n, 11);
  for (std::size_t i = 200; i < n; ++i) x[i] = 0.0;  // a 0.2 s burst, then nothing
  const Resonator res{r, theta};
  const std::vector<double> y = res.apply(x);
  for (double a : {0.0, 5.0}) {
    ImpactOptions o;
    o.sample_rate = fs;
    o.decay = a;
    o.response_std = {0.01};
    const FrfData d = impact_frf(x.data(), {y.data()}, n, o, "test", "F", {"y"});
    EXPECT_EQ(d.estimator, "impact");
    EXPECT_EQ(d.decay, a);
    ASSERT_EQ(d.f_hz.size(), n / 2);
    double worst = 0, w2 = 0;
    for (std::size_t i = 0; i < n; ++i) w2 += std::exp(-2 * a * double(i) / fs);
    for (std::size_t k = 0; k < d.f_hz.size(); ++k) {
      const cd z1 = std::exp(-cd(a, 2 * kPi * d.f_hz[k]) / fs);  // z⁻¹ at s = a + iω
      const cd exact = 1.0 / (1.0 - 2 * r * std::cos(theta) * z1 + r * r * z1 * z1);
      worst = std::max(worst, std::abs(d.channels[0].H[k] - exact) / std::abs(exact));
      cd X = 0;
      for (std::size_t i = 0; i < n; ++i) X += std::exp(-a * double(i) / fs) * x[i] * std::polar(1.0, -2 * kPi * double(k + 1) * double(i) / double(n));
      EXPECT_NEAR(d.channels[0].variance[k], 1e-4 * w2 / std::norm(X), 1e-9 * d.channels[0].variance[k]);
    }
    // The response left at the record's end, r^(n−200) e^{−aT}: 0.15 of its start unwindowed (the
    // transform's wrap-around spoils the ratio), 3e-10 under e^{−5t}.
    std::printf("a = %g 1/s: largest relative error %.2e\n", a, worst);
    if (a > 0) { EXPECT_LT(worst, 1e-6); }
    else EXPECT_GT(worst, 1e-2);
  }
}
