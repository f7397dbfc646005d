#pragma once
// One identification run: scenario (+ optional data file) → estimates, iteration history,
// identifiability, written as identify.json (docs/theory.md §10) and fit.csv (t, measured, predicted).
//
// The fit test (fit_test.h, docs/theory.md §7.6): the run is converged only when the optimiser
// stopped on a convergence test AND the model at the estimate explains the data. When it does not,
// although the optimiser stopped on a convergence test (a false convergence), up to
// identification.restarts further attempts are made from the starting point — the other start of
// sectional parameters (coarse to fine over tied blocks, tied_parameterization.h, after a plain
// first attempt; the plain run after a coarse-to-fine one: identification.start), then the run's
// method with a horizon continuation four times as cautious — and the best attempt (converged and
// explaining the data, else explaining it, else the lowest cost over the whole record) is the
// result; every attempt is reported.
//
// Identifiability (identifiability.h): Fisher-information std, resolution and the flags, at the
// estimate; the uncertainty interval (interval.h) from them, a refit on the first half of the
// record, and the consider shifts of the scenario's declared uncertainties
// (identification.uncertain).
#include <algorithm>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scoleid/identify/inverse/fit_test.h"
#include "scoleid/identify/inverse/identifiability.h"
#include "scoleid/identify/inverse/interval.h"
#include "scoleid/identify/inverse/modal_uncertainty.h"
#include "scoleid/identify/inverse/optimizers.h"
#include "scoleid/identify/run/problem.h"
#include "scoleid/identify/run/residual_bands.h"
#include "scoleid/identify/run/start_check.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/run_directory.h"

namespace scoleid::identify {

struct RunOptions {
  std::optional<std::string> data_csv;
  std::optional<io::Method> method;  // unset = the scenario's (auto resolved by run/strategy.h)
  bool compute_std = true;     // identifiability and the uncertainty interval
  bool verbose = true;         // print the iteration table on stdout as it goes
  std::optional<int> max_iterations;
  // A signal (or the wall-time limit's SIGALRM, io::request_interrupt) during the optimiser or the
  // assessment ends the run with the last iterate reached as its result instead of throwing
  // io::Interrupted: termination "interrupted", not converged, not assessed, interrupted_by set,
  // the interrupt cleared (the caller writes the outputs and exits 128 + signal, or 1 at the
  // wall-time limit). A signal before the first iterate still throws, and so does any signal in a
  // nonlinear-model run (identification.model: nonlinear).
  bool keep_interrupted = false;
};

struct RunResult {
  std::string scenario;
  io::Model model = io::Model::Linear;  // identification.model
  io::Method method = io::Method::GaussNewton;  // the optimiser used (auto resolved)
  std::vector<std::string> names;
  VectorXd initial, estimate;
  std::map<std::string, double> truth;
  OptimizerSummary summary;
  ObjectiveCounters counters;
  Identifiability ident;
  UncertaintyInterval interval;
  FitTest fit;  // at the estimate
  // identification.initial_state: estimate (docs/theory.md §6.9): the basis modes' frequencies at
  // the start values [Hz], and the initial state's coefficients at the estimate in them (the m
  // displacement coefficients, then the m velocity ones; M-orthonormal modes). Empty from rest.
  std::vector<double> initial_state_hz;
  VectorXd initial_state_coefficients;
  // The identified model's elastic modes, lowest first, with their propagated uncertainty
  // (inverse/modal_uncertainty.h); empty where the model has none below the data's Nyquist frequency.
  std::vector<ModalEstimate> modes;
  // The record's own modes at the estimate (inverse/record_modes.h; empty where not assessed).
  RecordModes record_modes;
  struct Attempt {
    std::string strategy;
    io::Method method = io::Method::GaussNewton;  // the optimiser of its last stage
    std::string termination;
    bool optimizer_converged = false;
    double cost = 0;  // J over the whole record
    int iterations = 0;
    bool explains_data = false;
    std::string fit_message;
    VectorXd estimate;  // where it ended
    // The coarse-to-fine levels before the full run (docs/theory.md §7.6), if any: blocks per
    // family, the level's time step, iterations, its cost, and whether its fit was within noise and
    // discretisation on the full model (which ends the ladder).
    struct Level {
      int blocks = 0;
      double step = 0, cost = 0;
      int iterations = 0;
      std::string termination;
      bool explained = false;
    };
    std::vector<Level> levels;
  };
  std::vector<Attempt> attempts;  // the first is the plain run, or the coarse-to-fine ladder's
  int chosen_attempt = 0;
  // A measured record's sensors against the model at the first attempt's start (start_check.h):
  // empty sensors when not checked.
  StartCheck start_check;
  // Where the residual at the estimate sits in frequency, by the identified modes (residual_bands.h);
  // empty bands when the run kept no outputs at the estimate.
  ResidualBands residual_bands;
  // The smoothness prior (identification.smoothness): its weight, and with the discrepancy
  // principle the weights tried, whether one met it, and the noise's expected misfit.
  double smoothness_weight = 0.0;
  struct SmoothnessStep {
    double weight, data_misfit, prior_cost;
    int iterations;
    bool converged;
  };
  std::vector<SmoothnessStep> smoothness_path;
  double smoothness_expected_misfit = 0.0;
  bool smoothness_met = false;
  // The optimiser stopped on a convergence test and the model explains the data (and, with the
  // discrepancy principle, a weight met it), and the data determine at least one estimated
  // parameter where that was assessed: a point the data leave wholly undetermined (noise far above
  // the signal, three samples) is the start's, not the data's, however well it "fits".
  bool converged() const {
    return summary.converged() && fit.explains_data && (smoothness_path.empty() || smoothness_met) && !determines_nothing();
  }
  // Identifiability was assessed and flags every estimated parameter.
  bool determines_nothing() const {
    return !ident.identifiable.empty() &&
           std::none_of(ident.identifiable.begin(), ident.identifiable.end(), [](bool b) { return b; });
  }
  // Every attempt's iterations with its coarse-to-fine levels (summary.iterations_done is the
  // chosen run's alone).
  int iterations_all_attempts() const {
    int n = 0;
    for (const auto& a : attempts) n += a.iterations;
    return n;
  }
  VectorXd half_record_estimate;
  bool half_record_converged = false;
  double wall_seconds = 0;
  double identifiability_seconds = 0;
  MatrixXd predicted;  // the model's outputs at the estimate, when the run kept them (nonlinear)
  Eigen::MatrixXcd frf_model;  // a frequency-domain run's model FRFs at the estimate (lines × sensors)
  std::string frf_start_note;  // how its fit started (the peaks' start, run/frf_run.h)
  long frf_passes = 0, frf_factorisations = 0;  // its work: passes over the lines, complex LU factorisations
  // The signal that ended the run (RunOptions::keep_interrupted; SIGALRM: the wall-time limit), 0
  // when it ran to its end; and where it stood then.
  int interrupted_by = 0;
  std::string interrupted_note;
  double integrator_step = 0.0;  // the nonlinear model's largest step (identify.json integrator.step)
  nlohmann::json to_json(const Problem& p) const;
  // The summary table scole-identify prints: per parameter initial, estimate, truth, relative
  // error, std, resolution and interval (or why not identifiable); then the optimiser's brief
  // report with the solve counts and the wall time.
  std::string FullReport() const;
};
// The modes of the model at r.estimate with the uncertainty of r.ident and r.interval (those below
// the data's Nyquist frequency, at most ten).
// `verbose`: on a large mesh (1000 degrees of freedom or more, where each dense eigen-solution
// takes seconds) one progress line says how many it takes.
void estimate_modes(const Problem& problem, RunResult& r, bool verbose = false);
// A result with the problem's scenario, names, starting values and truth filled in.
RunResult start_result(const Problem& problem, io::Model model);

RunResult run_identification(Problem& problem, const RunOptions& options);
// The rank of two attempts: converged and explaining the data, then explaining it, then the cost.
// With data_values N > 0 a lower cost must be lower by more than J/N (the same minimum reached twice
// differs by rounding only).
bool better_attempt(const RunResult::Attempt& a, const RunResult::Attempt& b, long data_values = 0);
// identification.model: nonlinear (nonlinear_run.cpp; run_identification hands over to it): the
// optimiser, the fit test, one cautious restart, the Fisher analysis and the uncertainty interval
// (without declared uncertainties: those it does not propagate, and then gives no interval).
RunResult run_nonlinear_identification(Problem& problem, const RunOptions& options);
// The first half of a record (samples up to the middle time): the half-record refit's data.
Measurements first_half(const Measurements& data);
// A parameter whose interval is too wide (interval.h) is flagged not identifiable, with the reason.
void flag_wide_intervals(RunResult& r);

// identification.model_error, with the automatic value resolved (io/scenario.h).
double model_error(const Problem& problem);
// The fit test at q (one forward solve on the identifier's model, one on twice its elements at
// a quarter of its step for the discretisation estimate, side by side; skipped if that model
// cannot be built). With `discretisation` (samples × sensors) that estimate is taken as given and
// only the identifier's model is solved. `meanwhile` (when set, and the doubled mesh is solved) runs
// on this thread once the identifier's own solve is done, while the doubled mesh's goes on: work
// for one core that would otherwise wait.
FitTest test_fit(const Problem& problem, Objective& objective, const VectorXd& q,
                 const MatrixXd* discretisation = nullptr, const std::function<void()>& meanwhile = {});

// The fit table: per sensor <name>_measured, <name>_predicted (Y, samples × sensors) and
// <name>_residual (predicted − measured) at the sample times.
io::DataTable fit_table(const Measurements& data, const MatrixXd& Y);
// The model's outputs at a run's estimate (the fit test's, else one forward solve): fit.csv's
// predicted columns.
MatrixXd predicted_outputs(Problem& problem, const RunResult& r);

// Writes identify.json, fit.csv, fit.gp and (with gnuplot) fit.png into the run directory's
// staging area; the caller commits them as one unit (io/run_directory.h).
void write_outputs(io::RunDirectory& dir, Problem& problem, const RunResult& r);
// The file names write_outputs produces (what a RunDirectory for them may replace).
inline std::vector<std::string> output_files() {
  return {"identify.json", "fit.csv", "fit.gp", "fit.png", "spectrum.csv", "spectrum.gp", "spectrum.png", "start_frf.csv", "start_frf.gp", "start_frf.png"};
}

}  // namespace scoleid::identify
