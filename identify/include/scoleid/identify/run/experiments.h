#pragma once
// Several experiments identified together (docs/theory.md §6.5): one parameter vector fitted to
// several runs — each with its own inputs, sensors and data, in the time domain or, when its
// scenario says identification.domain: frequency, as FRFs (frf_run.h, inverse/frf_misfit.h) — and
// optionally to measured modes, the cost the sum of theirs (inverse/joint_misfit.h).
//
// The experiments file (YAML; paths relative to the file):
//   experiments: NAME                 # names the run
//   description: "..."
//   threads: 0                        # concurrent experiment solves; 0 = the machine's threads
//   runs:                             # time- or frequency-domain runs (may be empty with modes)
//     - {name: pulse, scenario: pulse.yaml | built-in name, data: pulse/truth.csv}   # data optional
//   modes: {file: modes.csv, scenario: model.yaml}   # optional; scenario default: the first run's
// Every run estimates the same parameters from the same starting values (checked); the first
// run's (or the modes scenario's) identification section sets the method, tolerances and
// iteration limit. A run without `data` synthesises its own (problem.h).
//
// Weights. With time-domain runs only, each run keeps its default relative weights (its J is the
// relative mean-square misfit), so runs with similar relative noise count alike. When every
// sensor of every run has a stated noise level, or modal data are combined with time data, the
// weights are those of the likelihood instead: R_kk = n / (σ_k² W), n the run's samples and
// W = E∫ñ² the integral of the data interpolant of unit white noise over the record
// (Measurements::white_noise_integral), so white noise of the stated level adds ½ per sample to J
// in expectation, as it does to ½χ²: the runs and the modal ½χ² are on one scale. A
// frequency-domain run's misfit is ½χ² of its FRFs' variances already. Modal data or a
// frequency-domain run combined with a time run whose noise level is not stated is refused. With relative weights the
// reported std, the Cramér–Rao bound, may be optimistic (identify.json says so). Every setting of
// the fit (method, tolerances, continuation) is the first run's (or the modes scenario's).
//
// Convergence: the optimiser stopped on a convergence test AND every experiment explains its data
// (a time run by its fit test, fit_test.h; a frequency-domain run by frf_fit_test, frf_run.h;
// modal data when their χ² lies within ν + 3√(2ν), ν the
// residuals less one per unit-normalised shape, less P when the modes are the only data).
// Identifiability: the Fisher informations add (independent noise), so the joint std comes from
// Σ_e F_e; each experiment's own F_e at the joint estimate tells what it determines alone. No
// half-record (or half-band) refit and no consider terms are run (the single-run interval,
// interval.h): identify.json says so in place of an interval.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scoleid/identify/inverse/fit_test.h"
#include "scoleid/identify/inverse/identifiability.h"
#include "scoleid/identify/inverse/interval.h"
#include "scoleid/identify/inverse/optimizers.h"
#include "scoleid/identify/run/problem.h"
#include "scoleid/io/modal_data.h"
#include "scoleid/io/uff_modes.h"
#include "scoleid/io/run_directory.h"

namespace scoleid::identify {

struct ExperimentsSpec {
  std::string name, description, source;
  struct Run {
    std::string name, scenario;
    std::optional<std::string> data;
  };
  std::vector<Run> runs;
  std::optional<std::string> modes_file;
  std::string modes_scenario;  // "" = the first run's
  // For modes in a Universal File (datasets 55): the standard deviations and stations it does not
  // state (io/uff_modes.h); given = any of them was written.
  io::UffModesOptions modes_uff;
  bool modes_uff_given = false;
  int threads = 0;
};

struct ExperimentsOptions {
  std::optional<io::Method> method;  // unset = the lead scenario's (auto resolved by run/strategy.h)
  bool compute_std = true;
  bool verbose = true;
  std::optional<int> threads;  // overrides the file's
  std::optional<int> max_iterations;
};

struct ExperimentsResult {
  std::string name;
  io::Method method = io::Method::GaussNewton;
  std::vector<std::string> names;
  VectorXd initial, estimate;
  std::map<std::string, double> truth;
  OptimizerSummary summary;
  int threads = 1;
  std::string weighting;  // "relative" | "likelihood"
  struct Experiment {
    std::string name, kind, data_source;  // kind: "time" | "frf" | "modal"
    double cost = 0;                      // J_e at the estimate
    double share = 0;                     // J_e / J
    long data_values = 0;
    std::vector<std::string> channels;    // sensors (time) or "f<label>", "zeta<label>", "shape<label>" (modal)
    std::vector<double> residual_rms;     // per channel, in its unit (modal: in stated stds)
    bool explains_data = false;
    std::string fit_message;
    Identifiability alone;                // this experiment's Fisher information alone, at the joint estimate
    ObjectiveCounters counters;           // a time run's solves
    long factorisations = 0;              // a frequency-domain run's: complex LU factorisations, one per line and pass
  };
  std::vector<Experiment> experiments;
  Identifiability ident;  // joint
  std::string std_note;   // why the std may be weaker than stated ("" if it is not)
  // Measured modes alone (no time record): the uncertainty interval 2·√(std² + resolution²) from
  // the joint Fisher information (docs/theory.md §8.2; no half-record refit applies to a mode
  // set), a parameter whose interval exceeds half its value flagged in `ident`. Empty otherwise.
  UncertaintyInterval interval;
  double wall_seconds = 0;
  bool converged() const;
  nlohmann::json to_json() const;
};

// The loaded problems (kept for the outputs).
struct ExperimentsProblem {
  ExperimentsSpec spec;
  std::vector<std::unique_ptr<Problem>> runs;
  // Modal data and the structure they are compared with.
  std::optional<io::ModalData> modes;
  std::unique_ptr<io::Scenario> modes_scenario;
  std::unique_ptr<FEStructure> modes_structure;
  std::unique_ptr<Parameterization> modes_params;
};
ExperimentsResult run_experiments(ExperimentsProblem& problem, const ExperimentsOptions& options);

// identify.json, fit-<run>.csv (+ .gp, .png) per time run, modes-fit.csv with modal data.
std::vector<std::string> experiments_output_files(const ExperimentsSpec& spec);
void write_experiments_outputs(io::RunDirectory& dir, ExperimentsProblem& problem, const ExperimentsResult& r);

}  // namespace scoleid::identify
