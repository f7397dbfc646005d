#pragma once
// Starting values from the record's spectrum (docs/theory.md §7.6).
//
// Far from the solution a time-domain fit of a lightly damped record sees mostly phase: a model
// whose modes are 20 % off slips a cycle every five, and the cost has a valley at each slip. The
// frequencies themselves are in the data without any model, at the peaks of their spectrum. The
// record's dominant peak f_d (the Hann-windowed periodogram of each sensor, normalised by its
// total power and summed over the sensors) is compared with the same estimator on the model's
// predicted outputs at the start, f_m; if they differ, the start is moved so that the model's
// lowest elastic frequencies all scale by r = f_d / f_m:
//
//   Δ = Jᵀ (J Jᵀ)⁻¹ (log r) 1,   q_s = q ∘ exp(Δ),   J_ki = ∂ log f_k / ∂ log q_i
//
// the least change in log q that does it (a uniform beam with EI and ρA, f ∝ √(EI/ρA): EI × r and
// ρA / r, the change split evenly). Parameters that do not move the frequencies (damping) are left alone. J by
// central differences of the model's eigenproblem. A peak needs at least four of its cycles in
// the record and must lie below the Nyquist frequency; otherwise there is no spectral start.
#include <optional>
#include <string>

#include "scoleid/identify/fe/structural_model.h"
#include "scoleid/identify/inverse/measurements.h"
#include "scoleid/identify/inverse/parameterization.h"

namespace scoleid::identify {

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
  double data_hz = 0, model_hz = 0;
  std::string note;           // why there is none ("" when q is set)
};

// The spectral start from q0 given the model's outputs at q0 (samples × sensors at data.t).
SpectralStart spectral_start(const StructuralModel& model, const Parameterization& params, const VectorXd& q0,
                             const Measurements& data, const MatrixXd& predicted_at_q0);

}  // namespace scoleid::identify
