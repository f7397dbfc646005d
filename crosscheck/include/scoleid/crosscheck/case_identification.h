#pragma once
// One identification on one truth record, as a result row: the studies that run many of them
// (the mismatch suite, mismatch_suite.h; campaigns, campaign.h) share it, so their rows mean the
// same thing. docs/theory.md §11.5.
#include <nlohmann/json.hpp>

#include "scoleid/identify/run/problem.h"

namespace scoleid::crosscheck {

// Identifies `p` (with the Fisher step and the uncertainty interval) and returns
//   {converged, optimizer_converged, explains_data, fit_ratio, fit_test, termination, iterations,
//    seconds, parameters: [{name, truth, estimate, relative_error, std, resolution,
//    half_record_shift, half_width, relative_half_width, identifiable, covered}]}
// `covered`: the truth lies inside the reported interval (identifiable parameters only).
// Throws io::InputError if the truth file has no true value for an estimated parameter.
nlohmann::json identify_row(std::shared_ptr<identify::Problem> problem);

// Adds Gaussian noise of `relative` × each sensor's RMS, drawn from mt19937_64(seed), and states
// that level to the identifier (it is what a test engineer knows of the instrument).
void add_noise(identify::Problem& p, double relative, unsigned seed);

}  // namespace scoleid::crosscheck
