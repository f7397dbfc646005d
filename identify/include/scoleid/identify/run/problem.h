#pragma once
// An identification problem assembled from a scenario: the FE model on the identifier's mesh,
// the named parameters, the input signals and the measurements.
//
// Measurements come either from a data file (columns matched to the scenario's sensors by
// name; an input whose name is a column is driven by that column, piecewise linear, otherwise
// by the scenario's signal) or are synthesised: the same structure on a finer mesh
// (identification.data_elements, at least 2× the identifier's elements) with the true
// parameters, integrated with a 4× finer time step, sampled, plus each sensor's Gaussian noise
// (seeded) — so the identifier never sees its own discretisation.
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "scoleid/identify/fe/structure.h"
#include "scoleid/identify/inverse/measurements.h"
#include "scoleid/identify/inverse/objective.h"
#include "scoleid/identify/time/esdirk_stepper.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/scenario.h"

namespace scoleid::identify {

// How a data file's columns were used (identify.json "data_columns", and stderr).
struct ColumnUse {
  std::vector<std::string> sensors;               // matched to the scenario's sensors
  std::vector<std::string> inputs_from_data;      // inputs driven by their column
  std::vector<std::string> inputs_from_scenario;  // inputs driven by the scenario's signal
  std::vector<std::string> unused;                // columns that matched nothing
};

struct Problem {
  io::Scenario scenario;
  std::unique_ptr<FEStructure> structure;     // the FE model on the identifier's mesh
  std::unique_ptr<Parameterization> params;
  std::vector<io::Signal> signals;
  Measurements data;
  std::string data_source;                    // "synthetic (N elements)" or the CSV path
  std::map<std::string, double> true_values;  // by parameter name, where known
  std::vector<double> noise_std;              // per sensor: stated noise level, 0 = unknown
  std::vector<std::string> noise_origin;      // per sensor: "scenario" | "truth.json" | "" (unknown)
  ColumnUse columns;                          // with a data file
  const StructuralModel& model() const { return structure->model(); }
  ObjectiveOptions objective_options;
};

// Throws io::InputError for anything wrong with the scenario or the data.
std::unique_ptr<Problem> make_problem(const io::Scenario& scenario, const std::optional<std::string>& data_csv);

// Noise-free (or noisy, per the scenario) synthetic measurements on `elements` elements.
Measurements synthesize(const io::Scenario& scenario, int elements, double rtol, double step, bool add_noise);
// The identifier's fixed time step: identification.time_step if set, else
// min(sample interval, 0.3 / ω_{P+2}) with ω_{P+2} the FE frequency of flexible mode P + 2 at the
// starting parameters (P = number of estimated parameters), shortened when a damping parameter is
// estimated until the method's numerical damping ratio at ω_{P+2} h is at most 1 % of the
// smallest modal damping ratio of modes 1 … P + 2 (docs/theory.md §5.2). make_problem refuses a given step
// with ω_{P+2} h > 1 and any step whose trajectories exceed io/limits.h.
// ω_{P+2} (rad/s) at the starting parameters, or 0 for a structure without flexible modes.
double resolved_frequency(const StructuralModel& model, const Parameterization& params);
double identifier_step(const io::Scenario& scenario, const StructuralModel& model, const Parameterization& params);
// Numerical damping ratio −ln|R(i x)| / x of one step of a Runge–Kutta table at x = ω h.
double numerical_damping_ratio(const ButcherTable& table, double x);

}  // namespace scoleid::identify
