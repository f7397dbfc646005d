#include "scoleid/truth.h"

#include "scoleid/io/run_directory.h"

namespace scoleid {

Truth simulate_truth(const io::Scenario& scenario, const TruthOptions& options) { return model::run_truth(scenario, options); }

void write_truth(const Truth& truth, const std::string& dir) {
  io::RunDirectory run_dir(dir, model::output_files(), "scoleid");
  model::write_truth(truth, run_dir);
  run_dir.commit();
}

}  // namespace scoleid
