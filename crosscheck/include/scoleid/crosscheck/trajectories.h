#pragma once
// The same inputs through both models at the same parameters (docs/theory.md §11.2).
//
// The Simbody truth runs at n, 2n, 4n segments (noise-free); the FE model of the same structure
// (io::truth_scenario: truth.overrides applied) runs at the truth's physical parameters on N
// elements with the ESDIRK integrator at a step that resolves its first flexible modes finely
// (trajectories.cpp; the sampling interval / 4 at most), driven by the scenario's exact
// input signals (not the sampled input columns), so the difference is the chain's lumping plus the
// FE's own discretisation, and nothing else. Per sensor k and level n:
//     d_k(n) = ‖y_k^chain(n) − y_k^FE‖₂ / ‖y_k^chain(n)‖₂   over the sample times,
// (and, for SCOLE on request, the same for the nonlinear FE model beside the linear one),
// with the observed rate log2(d_k(n) / d_k(2n)) from the two finest levels (2 for the chain's
// lumping as long as the FE's error is smaller).
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "scoleid/crosscheck/table.h"
#include "scoleid/crosscheck/truth_levels.h"
#include "scoleid/io/scenario.h"

namespace scoleid::crosscheck {

struct TrajectoryOptions {
  int segments = 0;      // first chain level; 0 = the scenario's truth.segments
  int levels = 3;        // n, 2n, 4n
  int elements = 0;      // FE mesh; 0 = 4 × identification.elements
  double fe_step = 0.0;  // FE time step; 0 = resolve the first 5 flexible modes with ω h <= 0.03
  // SCOLE: also the nonlinear FE model (fe/scole_nonlinear.h) on `nonlinear_elements` elements
  // (0 = the linear comparison's), stepped at fe_step, or when that is 0 at the automatic rule's
  // step on its own mesh (time/nonlinear_forward.h).
  bool nonlinear = false;
  int nonlinear_elements = 0;
  bool progress = false;
  bool IsValid(std::string* why) const;
};

struct SensorAgreement {
  std::string name, kind;
  std::vector<double> relative_rms;   // per level
  double rate = 0.0;                  // log2 of the ratio of the two finest levels (NaN with one)
  std::vector<double> nonlinear_relative_rms;  // per level, the nonlinear FE model (when run)
};

struct TrajectoryReport {
  std::string scenario;
  bool truth_overrides = false;
  int elements = 0;
  int nonlinear_elements = 0;  // 0: the nonlinear model was not run
  std::vector<int> segments;
  std::vector<std::string> input_kinds;   // e.g. "actuator1 force"
  std::vector<SensorAgreement> sensors;
  // The finest level's records for the overlay plot (samples × sensors).
  std::vector<double> t;
  Eigen::MatrixXd chain, fe, nonlinear;  // nonlinear: empty unless run
  std::vector<TruthLevel> truths;
  double fe_seconds = 0.0, nonlinear_seconds = 0.0, seconds = 0.0;
};

// Truth files go to `truth_root`/n<segments>/.
TrajectoryReport compare_trajectories(const io::Scenario& scenario, const TrajectoryOptions& options,
                                      const std::string& truth_root);

// The FE response of io::truth_scenario(scenario) at its true parameters, sampled at the times of
// the truth file `csv` (which also supplies the true values): (samples × sensors), and the file's
// measurements beside it.
struct FeResponse {
  std::vector<double> t;
  Eigen::MatrixXd fe, measured;
  std::vector<std::string> sensors, kinds;
};
// `step` 0: automatic, as TrajectoryOptions::fe_step.
FeResponse fe_response(const io::Scenario& scenario, const std::string& csv, int elements, double step);
// The same with the nonlinear SCOLE model at a step of at most `step` (0: automatic, as fe_response);
// other structures are refused.
FeResponse nonlinear_fe_response(const io::Scenario& scenario, const std::string& csv, int elements, double step);

Table trajectories_table(const TrajectoryReport& r);
// t, then <sensor>_chain, <sensor>_fe, <sensor>_residual per sensor (finest level).
Table overlay_table(const TrajectoryReport& r);
nlohmann::json to_json(const TrajectoryReport& r);

}  // namespace scoleid::crosscheck
