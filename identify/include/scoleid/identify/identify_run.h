#pragma once
// One identification run: scenario (+ optional data file) → estimates, iteration history,
// identifiability, written as identify.json (DESIGN §6) and fit.csv (t, measured, predicted).
//
// Identifiability: at the estimate, the Fisher information F = Gᵀ W G from the output
// sensitivities G = ∂y(t_i)/∂q at the samples, W = diag(1/σ_k²) with σ_k the sensor's noise
// standard deviation (from the scenario or truth.json), or, when no noise level is known, the
// residual RMS of that sensor. std_i = sqrt((F⁻¹)_ii): the Cramér–Rao bound. The condition number
// is that of F scaled to relative parameters (diag(q) F diag(q)). A parameter with a share > 0.1 in
// an eigenvector of that matrix whose eigenvalue is below 1e-12 of the largest is flagged "not
// identifiable", and the others' std come from F restricted to them; a relative std above 0.5 is
// flagged too.
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

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

struct Identifiability {
  VectorXd std;                 // per parameter (NaN when F is singular)
  double condition_number = 0;  // of the relative Fisher matrix
  std::vector<bool> identifiable;
  std::vector<double> noise_std;  // σ_k used per sensor
  std::string noise_source;       // "scenario" | "residual"
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
  nlohmann::json to_json(const Problem& p) const;
};

RunResult run_identification(Problem& problem, const RunOptions& options);

// Writes identify.json and fit.csv into dir (atomically). Throws io::InputError if dir cannot be made.
void write_outputs(const std::string& dir, Problem& problem, const RunResult& r);

}  // namespace scoleid::identify
