#pragma once
// The identifier's front door: one call identifies a scenario's parameters from data.
//
//   io::Scenario sc = io::load_scenario("paper-beam-1");
//   scoleid::Identification id = scoleid::identify_parameters(sc, scoleid::DataSource::file("truth.csv"), {});
//   std::cout << id.FullReport();            // the table scole-identify prints
//   id.write("run/beam");                    // identify.json, fit.csv, fit.gp (fit.png)
//   return id.exit_code();                   // 0 only when the run has earned "converged"
//
// scole-identify, the examples, the cross-check and the Python module all go through it; nothing
// of theirs reaches below. The pipeline behind it (docs/theory.md §10): the scenario validated
// (io/validation.h) → the problem built (structure, parameters, data; run/problem.h) → the
// strategy resolved (run/strategy.h) → the attempts (run/attempts.h) → the assessment of the
// estimate (run/assessment.h) → the report (run/run_report.cpp). Errors in the input throw
// io::InputError (one line naming the file, field and value) before any solve; a signal throws
// io::Interrupted.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scoleid/identify/fe/state_space.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/identify/run/problem.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/run_directory.h"
#include "scoleid/io/scenario.h"
#include "scoleid/io/types.h"

namespace scoleid {

// Where the measurements come from: a data file (header t,<columns>; sensors and inputs matched by
// name; a truth.json beside it gives noise levels and true values), a table in memory (the same
// columns; `name` stands for the file in messages; optional truth metadata, named `meta_name` in
// messages — "<name> (metadata)" when empty), or neither — then the scenario synthesises them on a
// finer mesh (run/problem.h).
struct DataSource {
  std::optional<std::string> csv;
  std::optional<io::DataTable> table;
  std::string name;
  std::optional<io::TruthMeta> meta;
  std::string meta_name;
  static DataSource synthetic() { return {}; }
  static DataSource file(std::string path) { return {std::move(path), std::nullopt, "", std::nullopt, ""}; }
  static DataSource in_memory(io::DataTable t, std::string name = "data table",
                              std::optional<io::TruthMeta> meta = std::nullopt, std::string meta_name = "") {
    return {std::nullopt, std::move(t), std::move(name), std::move(meta), std::move(meta_name)};
  }
};

struct IdentifyOptions {
  std::optional<io::Method> method;   // unset: the scenario's identification.method
  std::optional<int> max_iterations;  // unset: the scenario's identification.max_iterations
  bool compute_std = true;            // identifiability, std and the uncertainty interval
  bool verbose = false;               // the iteration table on stdout as the run goes
  // A signal during the optimiser or the assessment returns the last iterate reached, marked
  // interrupted and not converged (result().interrupted_by), instead of throwing io::Interrupted;
  // scole-identify's choice, so that a run stopped by a scheduler keeps its progress.
  bool keep_interrupted = false;
  bool IsValid(std::string* why) const;
};

// The result of one identification: the problem it solved and what the run found, with the
// verdict it has earned.
class Identification {
public:
  Identification(std::shared_ptr<identify::Problem> problem, identify::RunResult result);

  const identify::Problem& problem() const { return *problem_; }
  const identify::RunResult& result() const { return result_; }
  const std::vector<std::string>& names() const { return result_.names; }
  const Eigen::VectorXd& estimate() const { return result_.estimate; }

  // Converged: the optimiser stopped on a convergence test, the model at the estimate explains the
  // data (the fit test), and a discrepancy-principle prior found its weight.
  bool converged() const { return result_.converged(); }
  // 0 when converged, 1 otherwise (scole-identify's exit code).
  int exit_code() const { return converged() ? 0 : 1; }
  // Why the run is not converged, in one line ("" when it is).
  std::string verdict() const;
  // Things the user must know even of a converged run (e.g. no parameter identifiable).
  std::vector<std::string> warnings() const;

  // The identified linear FE model at the estimate (identify/fe/state_space.h): a state-space plant
  // (A, B, C, D over the scenario's inputs and sensors) and its modal model.
  identify::StateSpace state_space() const;
  identify::ModalModel modal_model() const;
  // Both as JSON (the file scole-identify --export-model writes; docs/theory.md §10.2).
  nlohmann::json model_json() const;
  // Writes them to FILE.json, or FILE.mat (MATLAB; io/mat_file.h, when the build has libmatio).
  // io::InputError for another extension or a .mat the build cannot write.
  void export_model(const std::string& path) const;

  // fit.csv's table: per sensor <name>_measured, <name>_predicted, <name>_residual at the times.
  io::DataTable fit_table() const { return identify::fit_table(problem_->data, identify::predicted_outputs(*problem_, result_)); }

  std::string FullReport() const { return result_.FullReport(); }
  nlohmann::json to_json() const { return result_.to_json(*problem_); }
  // identify.json, fit.csv, fit.gp and (with gnuplot) fit.png into the run directory's staging
  // area; the caller commits (io/run_directory.h). The second form makes the directory and commits.
  void write(io::RunDirectory& dir) const;
  void write(const std::string& dir) const;
  static std::vector<std::string> output_files() { return identify::output_files(); }

private:
  std::shared_ptr<identify::Problem> problem_;
  identify::RunResult result_;
};

// The problem a scenario and its data pose (validated; io::InputError before any solve).
// `verbose`: the build's long steps said as they start (identify::make_problem).
std::shared_ptr<identify::Problem> prepare(const io::Scenario& scenario, const DataSource& data, bool verbose = false);
// Identify a prepared problem.
Identification identify_parameters(std::shared_ptr<identify::Problem> problem, const IdentifyOptions& options);
// Both in one.
Identification identify_parameters(const io::Scenario& scenario, const DataSource& data, const IdentifyOptions& options);

}  // namespace scoleid
