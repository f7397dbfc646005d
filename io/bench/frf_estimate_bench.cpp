// frf_estimate_bench: the Welch FRF estimator (io/frf_estimate.h) on a long record, fed as a DAQ
// hands it over. One input and three responses at 51 200 Hz, generated on the fly in chunks of
// 65 536 samples: a seeded Gaussian input, each response that input through its own two-pole
// resonator y[n] = 2r cos θ y[n−1] − r² y[n−2] + x[n] plus a little noise. Segments of 65 536
// samples (0.78 Hz lines), Hann, 50 % overlap. Prints the wall time (the generation apart) and the
// process's peak resident memory (getrusage ru_maxrss), and checks H1 against the resonators'
// exact transfer functions at their peaks. Usage: frf_estimate_bench [seconds of record, 60].
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "scoleid/io/frf_estimate.h"

using Clock = std::chrono::steady_clock;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRate = 51200.0;
constexpr std::size_t kChunk = 65536;

struct Resonator {
  double a1, a2, y1 = 0, y2 = 0;
  Resonator(double f, double r) : a1(2 * r * std::cos(2 * kPi * f / kRate)), a2(-r * r) {}
  double operator()(double x) {
    const double y = a1 * y1 + a2 * y2 + x;
    y2 = y1;
    y1 = y;
    return y;
  }
  std::complex<double> exact(double f) const {
    const std::complex<double> z1 = std::polar(1.0, -2 * kPi * f / kRate);
    return 1.0 / (1.0 - a1 * z1 - a2 * z1 * z1);
  }
};

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;  // kilobytes on Linux
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 60.0;
  if (!(seconds > 2.0)) {
    std::fprintf(stderr, "usage: frf_estimate_bench [seconds > 2]\n");
    return 2;
  }
  const std::size_t total = std::size_t(seconds * kRate);
  std::vector<Resonator> res{{120.0, 0.999}, {1500.0, 0.998}, {7000.0, 0.995}};
  std::mt19937_64 rng(20240601);
  std::normal_distribution<double> gauss(0.0, 1.0);
  scoleid::io::WelchOptions o;
  o.sample_rate = kRate;
  o.segment = 65536;
  o.overlap = 0.5;
  scoleid::io::WelchFrf welch(3, o);
  std::vector<double> x(kChunk);
  std::vector<std::vector<double>> y(3, std::vector<double>(kChunk));
  double estimating = 0;
  const auto start = Clock::now();
  for (std::size_t at = 0; at < total; at += kChunk) {
    const std::size_t n = std::min(kChunk, total - at);
    for (std::size_t i = 0; i < n; ++i) {
      x[i] = gauss(rng);
      for (std::size_t s = 0; s < 3; ++s) y[s][i] = res[s](x[i]) + 0.01 * gauss(rng);
    }
    const auto t0 = Clock::now();
    welch.add(x.data(), {y[0].data(), y[1].data(), y[2].data()}, n);
    estimating += std::chrono::duration<double>(Clock::now() - t0).count();
  }
  const auto t0 = Clock::now();
  const scoleid::io::FrfData d = welch.result("bench", "force", {"r120", "r1500", "r7000"});
  estimating += std::chrono::duration<double>(Clock::now() - t0).count();
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("record %.0f s at %.0f Hz: %zu samples x 4 channels, %d segments of %ld, %d lines\n", seconds, kRate, total,
              d.averages, o.segment, d.lines());
  std::printf("wall %.3f s (estimator %.3f s, %.1f M samples/s per channel), peak RSS %.1f MB\n", wall, estimating,
              double(total) / estimating / 1e6, peak_rss_mb());
  const double f_peak[3] = {120.0, 1500.0, 7000.0};
  for (std::size_t s = 0; s < 3; ++s) {
    double worst = 0;  // relative error of H1 over the lines within 200 Hz of the peak
    for (int j = 0; j < d.lines(); ++j)
      if (std::fabs(d.f_hz[j] - f_peak[s]) < 200.0) {
        const std::complex<double> h = res[s].exact(d.f_hz[j]);
        worst = std::max(worst, std::abs(d.channels[s].H[j] - h) / std::abs(h));
      }
    std::printf("  %s: largest |H1 - H|/|H| within 200 Hz of the peak %.2e\n", d.channels[s].sensor.c_str(), worst);
  }
  return 0;
}
