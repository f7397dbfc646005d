#pragma once
// The assessment of a linear identification's estimate (docs/theory.md §8): the Fisher information
// at q̂ (standard deviations, resolution and the identifiability flags, identifiability.h), the
// mirror test of sectional profiles, the other-minimum test of the attempts, the half-record refit, the smoothing shift of a prior, the
// consider terms of the declared uncertainties and of the identifier's own discretisation, and from
// them the uncertainty interval (interval.h); a parameter whose interval is too wide is flagged.
#include <functional>
#include <vector>

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

// The consider terms of the scenario's declared tolerances (identification.uncertain; interval.h)
// at an estimate, whatever the data: for each, the scenario moved by its tolerance on both sides
// (one side at the edge of its valid range; a switch to its alternative), `outputs` of the model
// built from the moved scenario (a flat vector as `y0`, the outputs at the scenario's own values),
// their change d, and `shift(d)` the estimate's least-squares response to it (F⁻¹ Gᵀ W d over the
// parameters the Fisher test kept). A change that is zero or not finite gets a shift of 0 or NaN
// and a note saying so.
std::vector<ConsiderTerm> declared_consider_terms(const io::Scenario& scenario, int parameters, const VectorXd& y0,
                                                  const std::function<VectorXd(const io::Scenario&)>& outputs,
                                                  const std::function<VectorXd(const VectorXd&)>& shift);

// The Fisher information of data filtered to identification.band (band_filter.h): scaled by the
// filter's noise gain g, and the systematic residual counted beyond the noise's χ² band for g N
// independent values; unchanged without a band.
FisherInformation band_information(const Problem& problem, FisherInformation fi);
// The sensors with each one's stated noise level: the scenario's, else truth.json's (make_problem).
std::vector<io::SensorSpec> sensors_with_noise(const Problem& problem);
// Where the noise levels came from: "scenario", "truth.json", both, or the identifiability's own word.
std::string noise_origin(const Problem& problem, const std::string& fisher_source);

}  // namespace scoleid::identify
