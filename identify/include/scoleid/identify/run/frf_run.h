#pragma once
// An identification in the frequency domain (identification.domain: frequency; docs/theory.md §6.10).
//
// The data: the FRFs of the record or file, made and checked at the door (door/frf_door.h).
//
// The run. The misfit (inverse/frf_misfit.h) minimised by the scenario's method with the frequency
// continuation; the fit test on the weighted residual (below); the Fisher information JᵀJ of the
// weighted residuals, the identifiability flags and the interval (inverse/interval.h) of the noise,
// the systematic residual and, in place of the half-record refit, the shift of a refit on the lower
// half of the band (the lines up to the middle one, from q̂): a model error that grows with
// frequency — a frequency error growing with mode number, as a lumped or coarse model's does —
// moves the estimate between the band and its lower half, as a time-domain model error moves it
// between the record and its first half. Declared uncertainties (identification.uncertain) add their
// consider terms (interval.h): the model rebuilt with each moved by its tolerance, the change of the
// weighted residuals of every line, and the estimate's least-squares response to it. Outputs: identify.json as the time-domain run's (with an "frf" block), fit.csv
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

RunResult run_frf_identification(Problem& p, const RunOptions& options);
FitTest frf_fit_test(const Problem& p, FrfMisfit& misfit, const VectorXd& q);
// The Fisher information JᵀJ of the weighted residuals of every line at q (the noise the FRFs'
// variances, so stated): the run's, and a frequency-domain experiment's in a joint run.
FisherInformation frf_fisher(FrfMisfit& misfit, const VectorXd& q);
// The consider terms of the scenario's declared tolerances at q (above; none without them).
std::vector<ConsiderTerm> frf_consider_terms(const Problem& p, FrfMisfit& misfit, const Identifiability& ident, const VectorXd& q);

}  // namespace scoleid::identify
