#pragma once
// Frequency response functions of S responses to one input (a force), estimated from uniformly
// sampled time records (the result is io/frf_data.h). Two estimators: Welch averaging for any
// excitation, and a least-squares fit of known lines for steady sines and periodic multi-sines.
//
// Transform and phase. A segment of N samples x[n] at the sample rate fs has the transform
//   X_k = Σ_{n<N} w[n] x[n] e^{−i2πkn/N}   at the line f_k = k fs/N,
// w the window. A sinusoid x = Re(A e^{iωt}) at a line gives X_k ∝ A, so Y_k/X_k is the H = Y/F
// of frf_data.h (e^{+iωt} time dependence): a response delayed by τ has H = e^{−iωτ}.
//
// 1. Welch averaging (WelchFrf): random, burst, chirp, any excitation. The record is cut into K
//    segments of N samples, each starting hop = N − round(overlap·N) samples after the one before
//    (a last incomplete segment is left out). Nothing is removed from a segment: no mean, no trend
//    (DC is never a kept line; a slow drift leaks into the lowest lines through the window's side
//    lobes). Window: Hann, w[n] = (1 − cos(2πn/N))/2 (the periodic form), or rectangular, w = 1.
//    Over the segments j:
//      Sxx = Σ_j |X_j|²,   Syy = Σ_j |Y_j|²,   Sxy = Σ_j X_j* Y_j
//      H1 = Sxy/Sxx  (unbiased with noise on the response),   H2 = Syy/Sxy*  (noise on the input),
//      γ² = |Sxy|²/(Sxx Syy).
//    With noise on the input only, x = u + m, H1 → H Suu/(Suu + Smm) (biased low), H2 → H.
//
//    Variance. Write Y_j = H X_j + N_j, the noise N_j uncorrelated with the input, E|N_j|² = σ_N².
//    Given the input, Ĥ1 − H = Σ_j X_j* N_j / Sxx, so
//      E|Ĥ1 − H|² = Σ_j Σ_l X_j* X_l E[N_j N_l*] / Sxx².
//    Independent segments leave σ_N²/Sxx. Overlapping segments share samples: for an input and a
//    noise each white across the window's main lobe, both E[N_j N_l*] and the average of X_j X_l*
//    carry the window's overlap correlation (Welch 1967)
//      c(r) = Σ_n w[n] w[n + r·hop] / Σ_n w[n]²      (r = |j − l|; phases cancel in the product),
//    so E|Ĥ1 − H|² = F σ_N²/Sxx with F = 1 + 2 Σ_{r=1}^{K−1} (1 − r/K) c(r)², and K_eff = K/F
//    independent averages (Hann at 50 %: c(1) = 1/6, F → 1 + 2/36 = 1.056; no overlap: F = 1).
//    The noise is read from what the fit leaves, R = Σ_j |Y_j − Ĥ1 X_j|² = Syy − |Sxy|²/Sxx, whose
//    mean is K σ_N² less the F σ_N² the fitted gain takes (one complex degree of freedom), so
//      σ̂² = F R / ((K − F) Sxx) = (Syy − |Sxy|²/Sxx) / ((K_eff − 1) Sxx)
//         = |Ĥ1|² (1 − γ²) / (γ² (K_eff − 1)).
//    Without overlap and with Gaussian noise σ̂² is unbiased and |Ĥ1 − H|²/σ̂² follows F(2, 2K − 2),
//    mean (K − 1)/(K − 2). Leakage (the response to input outside a segment) is a noise to this
//    model and lands in R; the window's smoothing of a resonance sharper than its main lobe is a
//    bias it does not see. H2 carries the same σ̂²: its first-order value, valid at high coherence
//    (H2 = H1/γ²).
//    Streaming: add() takes chunks of any size; memory is O(N (S + 1)), never the record.
//
// 2. Harmonic lines (harmonic_frf): steady sines and periodic multi-sines of known frequencies
//    f_l (l < L). Each channel, sample i at t_i = i/fs (t = 0 at the first sample), is fitted by
//    least squares with the same 2L + 1 columns, a constant and every line jointly:
//      x(t) = c + Σ_l a_l cos ω_l t + b_l sin ω_l t,   ω_l = 2π f_l.
//    The normal matrix G = Φ'Φ is summed in closed form, Σ_{i<n} e^{iαi} = e^{iα(n−1)/2} sin(nα/2)/
//    sin(α/2) at α = ω_l ± ω_m (over fs), and Φ'x in one pass, O(n L), the cosines and sines by
//    rotation recurrences re-seeded every 1024 samples. The complex amplitude A_l = a_l − i b_l
//    (x = Re(A e^{iωt})); H = A_y/A_x. When every line holds a whole number of cycles in the record
//    (within 1e-9) the columns are orthogonal, G = diag(n, n/2, …), and A_l = (2/n) Σ_i x_i e^{−iω_l t_i},
//    one DFT bin per line.
//    Noise: per channel σ² = Σ_i r_i²/(n − 2L − 1), r the residual (noise and anything not listed,
//    taken as white: its share at a line is the broadband σ²). Cov θ = σ² G⁻¹, so
//      E|δA_l|² = σ² ((G⁻¹)_{a_l a_l} + (G⁻¹)_{b_l b_l})      (4σ²/n when orthogonal),
//    and to first order, the input's and the response's noise independent,
//      E|Ĥ − H|² ≈ (E|δA_y|² + |H|² E|δA_x|²) / |A_x|².
//
// 3. Impact (impact_frf): a hammer hit (or any input) recorded from rest to the response's decay,
//    one segment of the whole record. An exponential window w[n] = e^{−a n/fs} on the force and on
//    every response alike: since e^{−at} (h ∗ x)(t) = ((e^{−at} h) ∗ (e^{−at} x))(t), the windowed
//    transforms' ratio is the FRF at the complex frequency s = a + iω,
//      H_k = Y_k / X_k = H(a + iω_k),   Y_k = Σ_n w[n] y[n] e^{−iω_k n/fs}
//    (exact for a system at rest at the first sample whose windowed response has died out by the
//    last). A model told a (frf_data.h decay) is compared at s = a + iω and ζ stays unbiased; read as
//    iω, the window would add a/ω_j to each mode's damping ratio. Lines k = 1 … at fs/N spacing.
//    Noise: a response noise white of std σ_y gives E|δY_k|² = σ_y² Σ w², so
//      E|Ĥ − H|² = (σ_y² + |H|² σ_x²) Σ_n w[n]² / |X_k|²
//    (σ_x the force's noise, 0 when unknown): the levels are the caller's (stated, or a quiet
//    start's), not the record's scatter — one hit has none.
//
// All refuse bad arguments with std::invalid_argument (the caller names the source and turns it
// into an input error): a sample rate that is not positive, a segment shorter than 2 samples or
// longer than the record, overlap outside [0, 1), samples that are not finite, lines outside
// (0, fs/2), fewer than 2 segments, a line without input.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "scoleid/io/frf_data.h"

namespace scoleid::io {

enum class FrfWindow { Hann, Rectangular };
enum class FrfEstimator { H1, H2 };

struct WelchOptions {
  double sample_rate = 0;        // Hz, > 0
  long segment = 0;              // samples per segment N (> 1); lines every fs/N Hz
  double overlap = 0.5;          // fraction of a segment shared with the next, in [0, 1)
  FrfWindow window = FrfWindow::Hann;
  FrfEstimator estimator = FrfEstimator::H1;
  double f_min = 0, f_max = 0;   // lines kept: f_min < f <= f_max (f_max 0: fs/2); DC never kept
};

class WelchFrf {
 public:
  WelchFrf(int responses, WelchOptions options);
  ~WelchFrf();
  WelchFrf(WelchFrf&&) noexcept;
  WelchFrf& operator=(WelchFrf&&) noexcept;

  // The next n samples: input[i] and responses[s][i] for s < responses (the same instants).
  void add(const double* input, const std::vector<const double*>& responses, std::size_t n);
  // Segments averaged so far.
  int segments() const;
  // Lines kept, H1 or H2 per response with its variance and coherence (needs 2 segments or more).
  FrfData result(const std::string& source, const std::string& input_name,
                 const std::vector<std::string>& response_names) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Welch's effective number of independent averages of K segments, counting the correlation of
// adjacent segments only: K / (1 + 2c²), c the window's overlap correlation at the hop (Welch 1967).
double welch_effective_averages(int segments, FrfWindow window, double overlap);

struct LinesOptions {
  double sample_rate = 0;         // Hz, > 0
  std::vector<double> lines_hz;   // strictly increasing, in (0, fs/2)
  // The DFT shortcut when the lines hold whole cycles; false solves the general normal equations
  // even then (they agree; a check of the shortcut).
  bool dft_when_orthogonal = true;
};

// The lines' H of each response (estimator "lines", averages = whole periods of the lowest line).
FrfData harmonic_frf(const double* input, const std::vector<const double*>& responses, std::size_t n,
                     const LinesOptions& options, const std::string& source, const std::string& input_name,
                     const std::vector<std::string>& response_names);

struct ImpactOptions {
  double sample_rate = 0;              // Hz, > 0
  double decay = 0;                    // a [1/s], >= 0
  double f_max = 0;                    // lines kept f <= f_max (0: fs/2)
  std::vector<double> response_std;    // σ_y per response, > 0
  double input_std = 0;                // σ_x of the force, >= 0
};

// The record's FRFs at s = decay + iω (estimator "impact", averages 1, decay set).
FrfData impact_frf(const double* input, const std::vector<const double*>& responses, std::size_t n, const ImpactOptions& options,
                   const std::string& source, const std::string& input_name, const std::vector<std::string>& response_names);

}  // namespace scoleid::io
