#pragma once
// Starting values from the record's spectrum (docs/theory.md §7.6).
//
// Far from the solution a time-domain fit of a lightly damped record sees mostly phase: a model
// whose modes are 20 % off slips a cycle every five, and the cost has a valley at each slip. The
// frequencies themselves are in the data without any model, at the peaks of their spectrum. The
// record's peaks (the Hann-windowed periodogram of each sensor, normalised by its total power and
// summed over the sensors) are lined up with the same estimator's peaks on the model's predicted
// outputs at the start: of the shifts r = f_d,j / f_m,i of every pair, the one under which the
// model's peaks, scaled by r, fall within 5 % of the most of the record's (between as many, with the largest summed strength
// √(p_m p_d)); within a factor 10, between equals the smaller shift. Pairing the peaks by their
// pattern, not the strongest with the strongest, keeps a record whose third mode dominates from
// being read as the model's first (a uniform beam's frequencies stand in fixed ratios, so two
// peaks lined up fix r). r is the strength-weighted geometric mean over the pairs lined up. The
// start is then moved so that the model's lowest elastic frequencies all scale by r:
//
//   Δ = Jᵀ (J Jᵀ)⁻¹ (log r) 1,   q_s = q ∘ exp(Δ),   J_ki = ∂ log f_k / ∂ log q_i
//
// the least change in log q that does it (a uniform beam with EI and ρA, f ∝ √(EI/ρA): EI × r and
// ρA / r, the change split evenly). Parameters that do not move the frequencies (damping) are left alone. J by
// central differences of the model's eigenproblem. A peak needs at least four of its cycles in
// the record and must lie below the Nyquist frequency; otherwise there is no spectral start.
#include <optional>
#include <string>
#include <vector>

#include "scoleid/identify/fe/structural_model.h"
#include "scoleid/identify/inverse/measurements.h"
#include "scoleid/identify/inverse/parameterization.h"

namespace scoleid::identify {

// A peak of the sensors' summed normalised spectra: its frequency (Hz) and normalised power.
struct SpectralPeak {
  double f = 0.0, power = 0.0;
};
// The peaks of the sensors' summed normalised spectra (as dominant_frequency), strongest first:
// local maxima that are the largest within ±3 % of their frequency, at least 10⁻³ of the strongest
// in power, at most `max_peaks`.
std::vector<SpectralPeak> spectral_peaks(const std::vector<double>& t, const MatrixXd& values, std::size_t max_peaks = 8);

// The common frequency ratio r that lines the model's peaks up with the record's (header):
// pairs = the model's peaks within 5 % of a record's peak once scaled by r; data_hz, model_hz the
// strongest such pair.
struct PeakMatch {
  double ratio = 1.0;
  int pairs = 0;
  double data_hz = 0.0, model_hz = 0.0;
};
std::optional<PeakMatch> match_peaks(const std::vector<SpectralPeak>& data, const std::vector<SpectralPeak>& model);

// The frequency (Hz) of the largest peak of the sensors' summed normalised spectra, at least four
// cycles within the record and at least two bins above zero; nullopt when there is none.
// `values` is samples × sensors on the uniform grid of `t` (the first step taken as the grid's).
std::optional<double> dominant_frequency(const std::vector<double>& t, const MatrixXd& values);

// One-sided power spectral density of each column (mean removed, Hann window, no padding; the first
// 2^20 samples at most): f in Hz from the first bin above zero, psd in (unit)²/Hz.
struct Spectrum {
  std::vector<double> f;
  MatrixXd psd;  // bins × columns
};
Spectrum power_spectrum(const std::vector<double>& t, const MatrixXd& values);

struct SpectralStart {
  VectorXd q;                 // the start
  double data_hz = 0, model_hz = 0;  // the strongest pair of peaks lined up
  double ratio = 1.0;                 // the frequency ratio the start applies
  int pairs = 0;                      // the model's peaks lined up with the record's
  std::string note;           // why there is none ("" when q is set)
};

// The spectral start from q0 given the model's outputs at q0 (samples × sensors at data.t).
SpectralStart spectral_start(const StructuralModel& model, const Parameterization& params, const VectorXd& q0,
                             const Measurements& data, const MatrixXd& predicted_at_q0);

}  // namespace scoleid::identify
