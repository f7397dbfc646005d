#pragma once
// The Simbody truth at a sequence of chain resolutions n, 2n, 4n, ..., each written as the
// truth.csv / truth.json pair that scole-truth writes (docs/theory.md §10): the files are the only
// bridge from model/ to identify/, here as everywhere.
#include <string>
#include <vector>

#include "scoleid/io/scenario.h"
#include "scoleid/model/truth_run.h"

namespace scoleid::crosscheck {

struct TruthLevel {
  int segments = 0;
  std::string csv;          // path of its truth.csv
  double seconds = 0.0;     // wall time of the Simbody run
  model::SimulateSummary summary;
};

// Runs io::truth_scenario(scenario) with segments[k] segments and writes the pair into
// `root`/n<segments>/ (a RunDirectory each: complete or absent). `noise_free` drops every
// sensor's noise (for comparisons of the models themselves). The levels run concurrently, one
// per hardware thread; the first failure (in level order) is rethrown after all have stopped.
std::vector<TruthLevel> run_truth_levels(const io::Scenario& scenario, const std::vector<int>& segments,
                                         const std::string& root, bool noise_free, bool progress);

// n, 2n, 4n, ... (`levels` values); io::InputError beyond io/limits.h.
std::vector<int> refinement(int first, int levels, int limit, const std::string& what);

}  // namespace scoleid::crosscheck
