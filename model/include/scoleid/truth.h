#pragma once
// The truth's front door: one call simulates a scenario's structure in Simbody — the multibody chain
// of rigid segments with the springs and dampers of the mast or beam, the shuttle free-floating,
// the reflector and the proof masses — and samples its sensors (model/truth_run.h).
//
//   io::Scenario sc = io::load_scenario("paper-scole-1");
//   const scoleid::Truth truth = scoleid::simulate_truth(sc);
//   scoleid::write_truth(truth, "run/scole/truth");   // truth.csv + truth.json, as scole-truth writes
//
// The identifier never includes this header: the two meet only through the files it writes.
#include <string>

#include "scoleid/io/scenario.h"
#include "scoleid/model/truth_run.h"

namespace scoleid {

using TruthOptions = model::TruthOptions;
using Truth = model::TruthResult;

// The truth trajectory of io::truth_scenario(scenario) (truth.overrides applied). Throws
// io::InputError for a scenario the truth cannot represent, model::PlausibilityError when the motion
// leaves the identifier's linear range, std::runtime_error when the integration fails.
Truth simulate_truth(const io::Scenario& scenario, const TruthOptions& options = {});
// truth.csv and truth.json into `dir`, both or neither (io/run_directory.h).
void write_truth(const Truth& truth, const std::string& dir);

}  // namespace scoleid
