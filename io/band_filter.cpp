#include "scoleid/io/band_filter.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace scoleid::io {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr int kLowPassOrder = 8, kHighPassOrder = 4;
}  // namespace

BandFilter::BandFilter(double f_lo, double f_hi, double dt) : lo_(f_lo), hi_(f_hi), dt_(dt) {
  if (!(dt > 0) || !std::isfinite(dt)) throw std::invalid_argument("band filter: the sample interval must be positive");
  if (!(f_lo >= 0 && f_hi > f_lo && f_hi < 0.5 / dt))
    throw std::invalid_argument("band filter: needs 0 <= f_lo < f_hi < " + std::to_string(0.5 / dt) + " Hz (the Nyquist frequency)");
  // Each conjugate pair of the analog Butterworth prototype's poles gives s² + a s + 1 with
  // a = 2 sin((2k − 1) π / 2n); the bilinear transform with K = tan(π f_c dt) (pre-warped edge).
  auto add = [&](double fc, int order, bool high) {
    const double K = std::tan(kPi * fc * dt);
    for (int k = 1; k <= order / 2; ++k) {
      const double a = 2.0 * std::sin((2.0 * k - 1.0) * kPi / (2.0 * order));
      const double norm = 1.0 / (1.0 + a * K + K * K);
      Section s;
      if (high) {
        s.b0 = norm;
        s.b1 = -2.0 * norm;
        s.b2 = norm;
      } else {
        s.b0 = K * K * norm;
        s.b1 = 2.0 * s.b0;
        s.b2 = s.b0;
      }
      s.a1 = 2.0 * (K * K - 1.0) * norm;
      s.a2 = (1.0 - a * K + K * K) * norm;
      sections_.push_back(s);
    }
  };
  add(f_hi, kLowPassOrder, false);
  if (f_lo > 0) add(f_lo, kHighPassOrder, true);
}

std::vector<double> BandFilter::apply(const std::vector<double>& x) const {
  std::vector<double> y = x;
  for (const Section& s : sections_) {
    double x1 = 0, x2 = 0, y1 = 0, y2 = 0;
    for (double& v : y) {
      const double out = s.b0 * v + s.b1 * x1 + s.b2 * x2 - s.a1 * y1 - s.a2 * y2;
      x2 = x1;
      x1 = v;
      y2 = y1;
      y1 = out;
      v = out;
    }
  }
  return y;
}

std::complex<double> BandFilter::response(double f) const {
  const std::complex<double> zi = std::exp(std::complex<double>(0.0, -2.0 * kPi * f * dt_));  // z⁻¹
  std::complex<double> g = 1.0;
  for (const Section& s : sections_) g *= (s.b0 + s.b1 * zi + s.b2 * zi * zi) / (1.0 + s.a1 * zi + s.a2 * zi * zi);
  return g;
}

double BandFilter::noise_gain(std::size_t n) const {
  std::vector<double> impulse(n, 0.0);
  if (n > 0) impulse[0] = 1.0;
  double e = 0.0;
  for (double h : apply(impulse)) e += h * h;
  return e;
}

}  // namespace scoleid::io
