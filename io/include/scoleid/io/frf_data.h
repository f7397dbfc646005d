#pragma once
// Frequency response functions of one input to several sensors (docs/theory.md §6.10): what a
// shaker or hammer test hands over instead of (or made from) a time record.
//
// At each line f_k (Hz) and for each sensor s, H_s(f_k) is the complex ratio of the sensor's
// response to the input, in the sensor's unit per the input's unit (SI after conversion: m/N for a
// displacement sensor and a force, m/s²/N for an accelerometer). Phase convention: a response
// y(t) = Re(Y e^{iωt}) to an input f(t) = Re(F e^{iωt}) has H = Y/F, so a displacement lags a
// force above its resonance (H → −1/(ω² m) there).
//
// Each value carries its uncertainty: variance σ²_k = E|Ĥ − H|² of the complex estimate (the real
// and imaginary parts each hold half of it, independent), from the estimator (io/frf_estimate.h:
// Welch H1 from the segments' scatter, the harmonic fit's noise) or a file's coherence and averages.
// A line without a variance cannot be weighted and is an input error where it is fitted.
#include <complex>
#include <string>
#include <vector>

namespace scoleid::io {

struct FrfData {
  std::string source;                  // the file (or "<file>, Welch H1") for messages
  std::string input;                   // the input's name ("" when there is one and it is not named)
  std::string estimator;               // "H1", "H2", "lines", or "file"
  std::vector<double> f_hz;            // lines, strictly increasing, > 0
  int averages = 0;                    // segments averaged (Welch), periods (lines); 0 unknown
  // An exponential window e^{-decay t} on the force and the responses alike (impact_frf,
  // frf_estimate.h): the values are then H at s = decay + iω, not at iω [1/s]; 0 = none.
  double decay = 0.0;
  struct Channel {
    std::string sensor;                          // the scenario sensor it belongs to
    std::vector<std::complex<double>> H;         // one per line
    std::vector<double> variance;                // E|Ĥ − H|² per line (> 0)
    std::vector<double> coherence;               // γ² per line, where known (else empty)
  };
  std::vector<Channel> channels;
  int lines() const { return static_cast<int>(f_hz.size()); }
};

}  // namespace scoleid::io
