#pragma once
// The assessment of a linear identification's estimate (docs/theory.md §8): the Fisher information
// at q̂ (standard deviations, resolution and the identifiability flags, identifiability.h), the
// mirror test of sectional profiles, the other-minimum test of the attempts, the half-record refit, the smoothing shift of a prior, the
// consider terms of the declared uncertainties and of the identifier's own discretisation, and from
// them the uncertainty interval (interval.h); a parameter whose interval is too wide is flagged.
#include "scoleid/identify/run/identify_run.h"

namespace scoleid::identify {

// Fills r.ident, r.interval, r.half_record_* and r.identifiability_seconds. `options`: the run's
// optimiser options (with the prior's chosen weight), for the refits; `made_already`: the refits
// made earlier (assessment_refits with the same options), used when their estimate is r.estimate.
void assess_estimate(const Problem& problem, Objective& objective, const OptimizerOptions& options, RunResult& r,
                     const IntervalInputs* made_already = nullptr);

// The refits the interval needs at an estimate (interval.h): the same fit on the first half of the
// record, from the estimate (none for a record too short to halve into two samples: the interval is
// then not assessed), and with a prior the refit at a tenth of its weight (on `objective`). Fills
// the estimate and the refit fields of IntervalInputs. `sweep_threads` > 0 overrides the half
// record's ObjectiveOptions::sweep_threads (the numbers do not depend on it).
IntervalInputs assessment_refits(const Problem& problem, Objective& objective, const OptimizerOptions& options,
                                 const VectorXd& estimate, int sweep_threads = 0);

// The Fisher information of data filtered to identification.band (band_filter.h): scaled by the
// filter's noise gain g, and the systematic residual counted beyond the noise's χ² band for g N
// independent values; unchanged without a band.
FisherInformation band_information(const Problem& problem, FisherInformation fi);
// The sensors with each one's stated noise level: the scenario's, else truth.json's (make_problem).
std::vector<io::SensorSpec> sensors_with_noise(const Problem& problem);
// Where the noise levels came from: "scenario", "truth.json", both, or the identifiability's own word.
std::string noise_origin(const Problem& problem, const std::string& fisher_source);

}  // namespace scoleid::identify
