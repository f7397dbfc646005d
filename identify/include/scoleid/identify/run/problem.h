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

#include "scoleid/identify/fe/modal.h"
#include "scoleid/identify/fe/scole_nonlinear.h"
#include "scoleid/identify/fe/structure.h"
#include "scoleid/identify/inverse/measurements.h"
#include "scoleid/identify/inverse/objective.h"
#include "scoleid/identify/time/esdirk_stepper.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/frf_data.h"
#include "scoleid/io/time_grid.h"
#include "scoleid/io/scenario.h"

namespace scoleid::identify {

// The modes the identifier resolves (docs/theory.md §5.2). At the starting parameters, mode k of
// the undamped FE model (M-orthonormal φ_k, frequency ω_k) responds to the inputs with a dynamic
// amplitude of at most A_jk = |c_j φ_k|·|Σ_i φ_kᵀ b_i F_i(ω_k)|/ω_k at sensor j, F_i(ω) =
// ∫₀ᵀ f_i(t) e^{−iωt} dt the input's spectrum over the record (ω_k|c_j φ_k| for a velocity row,
// ω_k²|…| for an acceleration). Only modes below the sampling's Nyquist frequency π/Δt count (the
// samples cannot carry more); there are K_nyq of them. The identifier resolves
//     K = min(P + 2, K_nyq)
// modes, P the number of parameters: P parameters are fixed mostly by the first P modes, and a mode
// above Nyquist cannot be resolved from the samples (it aliases). For few parameters this is P + 2; for many the step stops
// shrinking at what the sampling carries. Also reported: K_data, the highest mode whose amplitude
// at some sensor is at least kModeContentThreshold of the largest mode's there (what the signal
// visibly contains; not used for the step: a weakly seen parameter can live in a mode far below
// that, docs/theory.md §5.2).
// `mode` = K (1-based among the flexible modes), `omega` = ω_K.
inline constexpr double kModeContentThreshold = 1e-4;
struct DataContent {
  int mode = 0;                 // K (0: no flexible mode below Nyquist)
  int content_mode = 0;         // K_data (reported)
  double omega = 0.0;           // ω_K [rad/s]
  double omega_first = 0.0;     // the lowest flexible mode at the start [rad/s] (0: none below Nyquist)
  double nyquist = 0.0;         // π / sample interval
  int modes_below_nyquist = 0;  // flexible modes below it
};
// How a data file's columns were used (identify.json "data_columns", and stderr).
struct ColumnUse {
  std::vector<std::string> sensors;               // matched to the scenario's sensors
  std::vector<std::string> inputs_from_data;      // inputs driven by their column
  std::vector<io::Interpolation> input_interpolation;  // how each of them is read between samples
  std::vector<std::string> inputs_from_scenario;  // inputs driven by the scenario's signal
  std::vector<std::string> unused;                // columns that matched nothing
  // Where each sensor's and data-driven input's values came from: its column, the column's unit
  // and where that was stated (header, file record, column_unit), and the factor into the
  // sensor's or input's unit (1 when no unit is stated: the values are taken as they are).
  struct Source {
    std::string name, column, from_unit, unit_stated_by, to_unit;
    double scale = 1.0;
    // The scenario's conditioning (io::Conditioning), when stated: the offset subtracted (in the
    // sensor's or input's unit), the factor sign·scale applied after it, and with detrend the
    // line removed (its mean and slope per second about the record's mid-time).
    bool conditioned = false;
    double offset_removed = 0.0, factor = 1.0;
    std::pair<double, double> trend_removed{0.0, 0.0};
  };
  std::vector<Source> sources;
  // An input driven by its column that jumps by more than a quarter of its range within one sample,
  // in a step (a change more than three times one of its neighbours') or an impact (a pulse over at most
  // 8 samples): between samples such a column is read piecewise linearly (interpolation auto), so each jump (a step, a bang-bang switch) is
  // spread over a sample and its centre moved by up to half a sample, which a ringing structure's
  // phase feels (docs/theory.md §11.3).
  struct SteppedInput {
    std::string name;
    double jump = 0, at = 0, sample = 0;  // largest jump, the time after it, the interval there
    bool scenario_signal = false;         // the scenario also gives the signal (signal_from: scenario)
    // A pulse (an impact): the signal ends where it began (within a quarter of its range), and
    // `pulse_samples` samples hold more than a tenth of its peak. 0 for a step.
    int pulse_samples = 0;
    bool cubic = false;  // read cubically all the same (interpolation: cubic): it overshoots at each jump
    // An impact's force window (conditioning.window auto; door/record_columns.cpp force_window): the column is
    // zero outside [window_from, window_to]; the hits found in it (time of each one's peak, and its
    // peak relative to the largest): two or more are a double hit.
    bool windowed = false;
    double window_from = 0, window_to = 0;
    std::vector<std::pair<double, double>> hits;
  };
  std::vector<SteppedInput> stepped_inputs;
  // The record's time (io/time_grid.h): the uniform grid it lies on (if it does) and whether the
  // times were replaced by it — a stated data.sample_rate, or a uniform clock written coarsely
  // (the column's jitter within its own rounding).
  io::TimeGrid time;
  bool time_regularised = false;
  // The record's quiet start (noise_from_quiet_start in problem.cpp): the samples before the first
  // input acts, from which sensors without a stated noise level get one. 0 samples: none used.
  double trigger_time = 0.0;
  int quiet_samples = 0;
  // data.window (fit_window in problem.cpp): the first and last times fitted; empty: the whole record.
  std::vector<double> window;
};

struct Problem {
  io::Scenario scenario;
  std::unique_ptr<FEStructure> structure;     // the FE model on the identifier's mesh
  std::unique_ptr<Parameterization> params;
  std::vector<io::Signal> signals;
  Measurements data;
  std::string data_source;                    // "synthetic (N elements)" or the CSV path
  // Where the data come from: synthesised by the scenario's own model family (its default
  // model_error is 0), a measured record (a file or a table) or a file of FRFs — to which the lab
  // defaults apply (quiet-start noise, force window, automatic band, spectral first start) —, or
  // put in by the caller (a closed-form series: another model, model_error 1 %).
  enum class DataOrigin { Synthesis, Record, FrfFile, Caller };
  DataOrigin origin = DataOrigin::Synthesis;
  bool measured() const { return origin == DataOrigin::Record || origin == DataOrigin::FrfFile; }
  std::map<std::string, double> true_values;  // by parameter name, where known
  std::vector<double> noise_std;              // per sensor: stated noise level, 0 = unknown
  std::vector<std::string> noise_origin;      // per sensor: "scenario" | "truth.json" | "pre-trigger" | "" (unknown)
  // Column units truth.json states (by column name), for columns whose file states none.
  std::map<std::string, std::string> meta_units;
  ColumnUse columns;                          // with a data file
  DataContent content;                        // the modes the step resolves (data_content)
  // identification.band (inverse/band_filter.h): the filter's noise gain g = Σh² (1 without a band):
  // the noise_std above are then the filtered data's, σ √g, and about g of the samples are
  // independent.
  double band_gain = 1.0;
  // How the band came about with identification.band: auto ("" when stated or not asked for):
  // the band chosen and why, or why the whole record is fitted.
  std::string band_note;
  // What the record says of its own channels before any fit (an input's static offset;
  // docs/data.md §2.5), one line each naming the channel.
  std::vector<std::string> warnings;
  bool build_progress = false;  // make_problem's `verbose`
  // Inputs driven by their column that read with a static offset (the warning above): the input's
  // index and the column's mean, which the start check sets aside before it judges signs and scales.
  std::vector<std::pair<std::size_t, double>> static_offsets;
  // identification.domain: frequency (run/frf_run.h): the FRFs fitted, each channel's model sensor,
  // the model input they are per unit of, the degrees of freedom of their variances (0: known), and
  // one line on how they were made.
  std::optional<io::FrfData> frf;
  std::vector<int> frf_sensors;
  int frf_input = 0;
  double frf_variance_dof = 0.0;
  std::string frf_note;
  const StructuralModel& model() const { return structure->model(); }
  ObjectiveOptions objective_options;
};

// Throws io::InputError for anything wrong with the scenario or the data. `verbose`: the build's
// long steps (a dense eigen-solution on a mesh of 1000 degrees of freedom or more) said on stdout
// (io::progress) before they start.
std::unique_ptr<Problem> make_problem(const io::Scenario& scenario, const std::optional<std::string>& data_csv,
                                      bool verbose = false);
// The same from a table in memory (columns matched as a file's are; `source` names it in messages),
// with the truth metadata that came with it, if any (`meta_source` names that).
std::unique_ptr<Problem> make_problem(const io::Scenario& scenario, const io::DataTable& table, const std::string& source,
                                      const io::TruthMeta* meta = nullptr, const std::string& meta_source = "",
                                      bool verbose = false);

// Measurements as a lab's file holds them: t, then each input's signal as the scenario states it,
// then each sensor's column (io::write_csv writes it).
io::DataTable measurement_table(const io::Scenario& scenario, const Measurements& m);
// Noise-free (or noisy, per the scenario) synthetic measurements on `elements` elements.
Measurements synthesize(const io::Scenario& scenario, int elements, double rtol, double step, bool add_noise,
                        int dirk_table = -1);
// The closed-form modal series (`terms` modes) of a uniform simply supported beam under the step
// load of the scenario's first input, at its first sensor and its sample times: data with no
// finite elements in them (std::invalid_argument for any other structure).
Measurements synthesize_series(const io::Scenario& scenario, int terms = 4000);
// The same from the nonlinear SCOLE model (identification.model: nonlinear) at a step of at most `step`.
Measurements synthesize_nonlinear(const io::Scenario& scenario, int elements, double step, bool add_noise);
// The starting model (the parameters' initial values) assembled, its natural frequencies and its
// modes, each computed once, when first asked: a problem's build asks for them several times (the
// data's content, the step's damping bound, a stated step's check). On a model of fewer than
// kSparseModesFrom degrees of freedom each is a dense eigen-solution of every mode (fe/modal.h);
// on a larger one, when the modes below `up_to` are few (sparse_modes_pay), just those, by the
// sparse solver of fe/lowest_modes.h — milliseconds where a dense solution takes minutes. `verbose`
// says on stdout (io::progress) what is solved on a model of kSparseModesFrom degrees of freedom or more.
class StartModes {
public:
  StartModes(const StructuralModel& model, const Parameterization& params, bool verbose = false);
  const StructuralModel& model() const { return model_; }
  const Parameterization& params() const { return params_; }
  const AssembledModel& ops() const { return ops_; }
  // Ascending [rad/s]: every mode's (natural_frequencies(M, K)), or on a large model at least
  // those below up_to.
  const std::vector<double>& frequencies(double up_to);
  // natural_modes(M, K), or on a large model at least the modes below up_to.
  const NaturalModes& modes(double up_to);
  // Below this a frequency is a rigid-body mode's (rigid_floor, fe/modal.h; after frequencies()).
  double rigid_below() const { return rigid_below_; }

private:
  bool sparse(double up_to);
  const StructuralModel& model_;
  const Parameterization& params_;
  bool verbose_;
  AssembledModel ops_;
  std::optional<std::vector<double>> frequencies_;
  std::optional<NaturalModes> modes_;
  bool frequencies_all_ = false, modes_all_ = false;  // from a dense solution of every mode
  bool sparse_failed_ = false;                        // the sparse solver gave up: dense from then on
  double solved_up_to_ = 0.0;                         // the sparse modes' band
  double rigid_below_ = 0.0;
  std::optional<int> below_count_;  // the Sturm count at counted_at_
  double counted_at_ = 0.0;
};

// from_data (identification.step_rule: data): K = K_data instead of min(P + 2, K_nyq).
DataContent data_content(StartModes& start, const std::vector<io::Signal>& signals, double t_end, double sample_interval,
                         bool from_data = false);
DataContent data_content(const StructuralModel& model, const Parameterization& params,
                         const std::vector<io::Signal>& signals, double t_end, double sample_interval,
                         bool from_data = false);
// The identifier's fixed time step: identification.time_step if set, else
// min(sample interval, 0.3 / ω_K), K = min(P + 2, modes below Nyquist) or, with
// identification.step_rule: data, K_data (data_content),
// shortened when a damping parameter is estimated until the method's numerical damping ratio at
// ω_K h is at most 1 % of the smallest modal damping ratio of modes 1 … K (docs/theory.md §5.2).
// That damping bound is met by one of two ESDIRK tables, the default third-order
// ESDIRK3(2)4L[2]SA (3 implicit stages) and the fourth-order ESDIRK4(3)6L[2]SA (5), whose
// damping grows as (ω h)⁵ instead of (ω h)³: the run takes the one with fewer implicit stages per
// second of record, and the third-order table whenever the bound does not shorten its step (and
// always for identification.model: nonlinear, whose stepper has its own third-order table).
// make_problem refuses a given step with ω_K h > 1 and any step whose trajectories exceed
// io/limits.h.
struct IdentifierStep {
  double step = 0.0;
  int dirk_table = -1;            // SolverOptions::dirk_table
  double third_order_step = 0.0;  // the step the third-order table alone would take (= step when it is taken)
};
IdentifierStep identifier_integration(const io::Scenario& scenario, StartModes& start, const std::vector<io::Signal>& signals);
IdentifierStep identifier_integration(const io::Scenario& scenario, const StructuralModel& model,
                                      const Parameterization& params, const std::vector<io::Signal>& signals);
double identifier_step(const io::Scenario& scenario, const StructuralModel& model, const Parameterization& params,
                       const std::vector<io::Signal>& signals);
// Numerical damping ratio −ln|R(i x)| / x of one step of a Runge–Kutta table at x = ω h.
double numerical_damping_ratio(const ButcherTable& table, double x);

}  // namespace scoleid::identify
