#pragma once
// An identification in the frequency domain (identification.domain: frequency; docs/theory.md §6.10).
//
// The data. Frequency response functions of the scenario's one input to every sensor:
//   - made from a time record (a data file, or the scenario's synthetic record) by
//       lines  the input's known lines (its sine and multisine terms, or identification.frf.lines):
//              a least-squares harmonic fit of every channel over the whole record, H = Y/X per
//              line, the variance from what the fit leaves in each channel (io/frf_estimate.h). For
//              steady sines and periodic multi-sines: no leakage, whatever the damping;
//       h1/h2  Welch's averaged segments (identification.frf.segment, overlap, window), the
//              variance from the segments' scatter (coherence); the lines up to 0.8 of Nyquist.
//     auto takes lines when the input's scenario signal is made of sines, else h1.
//   - or read from a UFF file of FRFs (function type 4, io/uff_frf.h) given as --data.
//   identification.band [f_lo, f_hi], when stated, keeps the lines within it. Every line's variance
//   is the data's own: the segments' scatter, the harmonic fit's remainder, a file's coherence or a
//   stated relative_std — never the model's residual. A variance estimated from ν degrees of
//   freedom is scaled by ν/(ν − 2), so that a value's expected weighted misfit is 1 (the F(2, ν)
//   law's mean), and the fit test's χ² band is widened by ν/(ν − 4) (its variance).
//
// The run. The misfit (inverse/frf_misfit.h) minimised by the scenario's method with the frequency
// continuation; the fit test on the weighted residual (below); the Fisher information JᵀJ of the
// weighted residuals, the identifiability flags and the interval (inverse/interval.h) of the noise,
// the systematic residual and, in place of the half-record refit, the shift of a refit on the lower
// half of the band (the lines up to the middle one, from q̂): a model error that grows with
// frequency — a frequency error growing with mode number, as a lumped or coarse model's does —
// moves the estimate between the band and its lower half, as a time-domain model error moves it
// between the record and its first half. Declared uncertainties are refused at the door. Outputs: identify.json as the time-domain run's (with an "frf" block), fit.csv
// (per line and sensor: measured and model real, imaginary, magnitude and phase, the value's std),
// fit.png (magnitude and phase, measured and model).
//
// Fit test. With r the weighted residuals of N values, d the doubled-mesh model's FRFs less the
// model's at q̂ (the discretisation estimate) and m the declared model error (a fraction of |Ĥ|):
//   explained when  Σ r² − N  <=  Σ_ks 2(4|d_ks|² + m²|Ĥ_ks|²)/σ²_ks + 3 √(2N κ),   κ = ν/(ν − 4) (1 for known variances)
// — the systematic χ² within what discretisation and model error allow, plus three standard
// deviations of the noise's χ².
#include "scoleid/identify/inverse/frf_misfit.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/io/frf_data.h"

namespace scoleid::identify {

// The FRFs of a problem with identification.domain: frequency, made from its time record (p.data,
// p.signals) and checked at the door (io::InputError naming the scenario field or the data).
void frf_from_record(Problem& p);
// The same from FRFs read from a file (`orders`: each channel's response derivative, 0 displacement,
// 1 velocity, 2 acceleration, converted to the scenario sensor's).
void frf_from_file(Problem& p, io::FrfData data, const std::vector<int>& orders);

RunResult run_frf_identification(Problem& p, const RunOptions& options);
FitTest frf_fit_test(const Problem& p, FrfMisfit& misfit, const VectorXd& q);

}  // namespace scoleid::identify
