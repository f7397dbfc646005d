#pragma once
// The identifier's front door for several experiments (docs/theory.md §6.5, §10.1b): the
// experiments file read and every run, the modal data and their scenarios checked and resolved
// into problems before any joint solve —
//   - the file: its fields, run names (unique, not "modes", fit for file names), a scenario and
//     a record per run, no record counted twice, modes with a scenario to compare them with;
//   - each run's scenario through the scenario and record doors (make_problem), and what a joint
//     run does not take refused (smoothness, start, band, uncertain, the nonlinear model);
//   - every run and the modes estimating the same parameters from the same starting values;
//   - modal data beside time runs only with every sensor's noise stated; modes the model can be
//     compared with at the start.
// io::InputError naming the file, the field and the value.
#include <memory>
#include <string>

#include "scoleid/identify/run/experiments.h"

namespace scoleid::identify {

ExperimentsSpec load_experiments(const std::string& path);
std::unique_ptr<ExperimentsProblem> make_experiments(const ExperimentsSpec& spec);

}  // namespace scoleid::identify
