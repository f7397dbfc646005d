#pragma once
// A causal Butterworth filter in second-order sections, run from rest on uniformly sampled data:
// a low-pass of order 8 at f_hi and, for f_lo > 0, a high-pass of order 4 at f_lo, by the bilinear
// transform with the edges pre-warped (|G| = 1/√2 at f_lo and f_hi, up to the other edge's
// influence, (f_lo/f_hi)^8). Two users: the identifier's fit band (identify/inverse/band_filter.h,
// docs/theory.md §6.8) and the truth's acquisition filter, an 8-pole anti-alias low-pass as a DAQ
// applies to every channel before it samples (truth.anti_alias_hz, docs/truth-guards.md).
//
// White noise of variance σ² leaves the filter with variance g σ² per sample, g = Σ h_i² (the
// impulse response's energy, about the band's share of the Nyquist range).
#include <complex>
#include <cstddef>
#include <vector>

namespace scoleid::io {

class BandFilter {
public:
  // Throws std::invalid_argument unless 0 <= f_lo < f_hi < 1/(2 dt).
  BandFilter(double f_lo, double f_hi, double dt);
  // The filtered samples, from rest (x on the uniform grid of step dt).
  std::vector<double> apply(const std::vector<double>& x) const;
  // G(e^{i 2π f dt}).
  std::complex<double> response(double f) const;
  // Σ_{i<n} h_i², the energy of the first n samples of the impulse response.
  double noise_gain(std::size_t n) const;
  double f_lo() const { return lo_; }
  double f_hi() const { return hi_; }

private:
  struct Section {
    double b0, b1, b2, a1, a2;  // y = b0 x + b1 x₋₁ + b2 x₋₂ − a1 y₋₁ − a2 y₋₂
  };
  std::vector<Section> sections_;
  double lo_, hi_, dt_;
};

}  // namespace scoleid::io
