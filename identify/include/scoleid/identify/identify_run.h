#pragma once
// One identification run: scenario (+ optional data file) → estimates, iteration history,
// identifiability, written as identify.json (DESIGN §6) and fit.csv (t, measured, predicted).
//
// Identifiability (identifiability.h): Fisher-information std, resolution and the flags, at the
// estimate.
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scoleid/identify/identifiability.h"
#include "scoleid/identify/optimizers.h"
#include "scoleid/identify/problem.h"

namespace scoleid::identify {

struct RunOptions {
  std::optional<std::string> data_csv;
  std::string method;          // empty = the scenario's (auto → gauss-newton for ≤ 16 parameters, else lbfgs)
  bool compute_std = true;
  bool verbose = true;         // print the iteration table on stdout as it goes
  std::optional<int> max_iterations;
};

struct RunResult {
  std::string scenario;
  std::string method;
  std::vector<std::string> names;
  VectorXd initial, estimate;
  std::map<std::string, double> truth;
  OptimizerSummary summary;
  ObjectiveCounters counters;
  Identifiability ident;
  double wall_seconds = 0;
  double identifiability_seconds = 0;
  nlohmann::json to_json(const Problem& p) const;
};

RunResult run_identification(Problem& problem, const RunOptions& options);

// Writes identify.json and fit.csv into dir (atomically). Throws io::InputError if dir cannot be made.
void write_outputs(const std::string& dir, Problem& problem, const RunResult& r);

}  // namespace scoleid::identify
