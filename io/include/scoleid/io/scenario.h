#pragma once
// Every field for users, by its path, with its unit, default and range: docs/scenario.md.
// The scenario: one YAML document that both the Simbody truth (model/) and the finite-element
// identifier (identify/) read. Each struct maps one-to-one onto a YAML section; every field has
// its default written here, and parse errors name the source, the field path and the value.
//
// Units are whatever consistent system the scenario uses (SI for the beam cases, slug-ft-s for
// SCOLE), stated by `units:` or not; the model computes in it unconverted. Only measured data are
// converted, from their columns' units into the sensors' and inputs' (io/units.h).
//
//   name, description
//   structure: beam | scole
//   beam:      { length, left, right, rho_A, EI: x | [x1..xN], zeta, c_kv, tip_mass, tip_inertia,
//                supports: { left|right: { k_w, k_theta, c_w, c_theta } },
//                attachments: [ { name, location, mass, inertia, k_w, k_theta, c_w, c_theta,
//                                 lumped_mass, lumped_k, lumped_c, lumped_k_ground } ] }
//   scole:     see ScoleSpec
//   inputs:    [ { name, at, kind, location, direction, unit, signal } ]
//   sensors:   [ { name, at, kind, location, direction, unit, noise_std } ]
//   units:     SI | slug-ft-s (optional: the unit system; sensor and input units must agree)
//   inputs/sensors may name their data column and its unit: column, column_unit
//   data:      { time_column, time_unit, sample_rate }  (how a measured data file is read)
//   simulation:{ duration, sample_interval, seed }
//   identification: { parameterization, estimate, initial, elements, data_elements, method, ...,
//                      uncertain: {field path: tolerance | alternative switch setting} }
//   truth:     { segments, integrator, accuracy, ..., large_motion,
//                overrides: { beam: {...} | scole: {...},
//                             sensors: [ { name, location, direction, bias, drift } ] } }
//              (the Simbody generator's settings; overrides: structure and sensor fields in which
//              the truth differs from the identifier's model — how a model-mismatch scenario is
//              written)
//
// Plausibility guards (docs/truth-guards.md): the truth refuses a run whose motion leaves the
// range the identifier's linear model describes — a proof mass beyond scole.actuator_stroke, a
// rotation beyond the small-rotation bound unless truth.large_motion is set.
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "scoleid/io/signal.h"
#include "scoleid/io/types.h"
#include "scoleid/io/units.h"

namespace scoleid::io {

enum class EndCondition { Pinned, Clamped, Free };
const char* to_string(EndCondition e);

// Euler–Bernoulli beam on s in [0, length] (docs/theory.md §2.1, §2.2):
//   rho_A w_tt - (d(s) w_st)_s + (c_kv w_sst)_ss + (EI(s) w_ss)_ss = loads,  d = 2 zeta sqrt(rho_A EI)
// EI holds one value (uniform) or N values on N equal-length sections. Two damping laws, either or
// both: zeta, the dimensionless square-root (Chen–Russell) damping ratio (every mode of a uniform
// pinned–pinned beam has damping ratio exactly zeta; d follows EI section by section), and c_kv,
// the Kelvin–Voigt (strain-rate) coefficient in units of EI × time (N·m²·s), one value for the
// whole beam. Both >= 0.
// A point element at station s of a member (docs/theory.md §2.5): a rigid mass m with rotary
// inertia J riding on the member's displacement w(s) and slope w_s(s), and springs and dashpots
// from that point to ground, k_w, c_w on w(s) and k_theta, c_theta on w_s(s). Every quantity is a
// named, estimable parameter when it is > 0 (point_element_quantities).
// An attachment may also carry a lumped attachment: a mass lumped_mass with a degree of freedom of
// its own, along w, joined to w(s) by a spring lumped_k with a dashpot lumped_c in parallel and to
// ground by a spring lumped_k_ground (a shaker's armature on its stinger and flexures, a tuned
// absorber); lumped_mass and lumped_k both > 0 when any of the four is.
struct PointElement {
  std::string name;
  double location = 0.0;
  double mass = 0.0, inertia = 0.0;
  double k_w = 0.0, k_theta = 0.0, c_w = 0.0, c_theta = 0.0;
  double lumped_mass = 0.0, lumped_k = 0.0, lumped_c = 0.0, lumped_k_ground = 0.0;
  bool has_lumped() const { return lumped_mass > 0.0 || lumped_k > 0.0 || lumped_c > 0.0 || lumped_k_ground > 0.0; }
};
// The quantities of a point element by field name (mass, inertia, k_w, k_theta, c_w, c_theta,
// lumped_mass, lumped_k, lumped_c, lumped_k_ground), in that order.
std::vector<std::pair<const char*, double PointElement::*>> point_element_fields();
// Fields only an attachment has, not a support: mass, inertia and the lumped attachment's.
bool attachment_only_field(const std::string& key);
// Fields that act on the displacement w(s) (the others on the slope w_s(s)).
bool displacement_field(const std::string& key);
// The parameter name of a point element's quantity: "supports.left.k_theta",
// "attachments.clamp.mass" (`group` is "supports" or "attachments").
std::string point_element_parameter(const std::string& group, const PointElement& e, const char* field);

struct BeamSpec {
  double length = 10.0;
  EndCondition left = EndCondition::Pinned;
  EndCondition right = EndCondition::Pinned;
  double rho_A = 67.0;
  std::vector<double> EI = {23000.0};
  double zeta = 0.0;   // Chen–Russell damping ratio (dimensionless)
  double c_kv = 0.0;   // Kelvin–Voigt coefficient (EI × time)
  double tip_mass = 0.0;     // rigid mass at s = length
  double tip_inertia = 0.0;  // its rotary inertia about the bending axis
  // An end's springs and dashpots to ground (`supports: {left: {...}, right: {...}}`), acting on
  // the degrees of freedom the end condition leaves free (a compliant clamp: `left: pinned` with
  // supports.left.k_theta). Each PointElement's name is its end, its location the end's station.
  std::vector<PointElement> supports;
  // Point elements at stations of the beam (`attachments: [{name, location, ...}]`): a sensor's or
  // a fixture's mass, a grounded spring. docs/theory.md §2.5.
  std::vector<PointElement> attachments;
};

// A planar frame of storeys (docs/theory.md §2.6): each storey `columns` identical vertical
// Euler–Bernoulli columns (mass per length rho_A, bending stiffness EI[k]) of height heights[k],
// clamped into a rigid floor block of mass floor_mass[k] at the top and into the floor below (the
// ground for the first storey) at the bottom; the columns inextensible. Motion in the frame's plane:
// w(s) the horizontal displacement at height s of a column, s from the ground. Stations (sensors'
// and inputs' `location`) are heights on the first column; at a floor's height, the floor's.
// Damping: square-root d = 2ζ√(ρA·EI[k]) on each column, as on a beam, and Kelvin–Voigt
// c = τ·EI[k] (stiffness-proportional: mode j's damping ratio τω_j/2).
struct FrameSpec {
  std::vector<double> heights = {0.3, 0.3, 0.3, 0.3};  // storey heights, bottom to top
  int columns = 2;                                     // columns per storey (at least 2: they hold the floor from turning)
  double bay = 0.2;                                    // distance between neighbouring columns (the truth's geometry)
  double rho_A = 0.3925;                               // a column's mass per length
  std::vector<double> EI = {3.333, 3.333, 3.333, 3.333};  // a column's EI per storey
  std::vector<double> floor_mass = {1.0, 1.0, 1.0, 1.0};  // each floor block's mass, bottom to top
  double zeta = 0.0;  // square-root (Chen–Russell) damping ratio of the columns
  double tau = 0.0;   // Kelvin–Voigt time constant: each column's c = tau·EI; mode j damped by tau·ω_j/2
  double height() const {
    double H = 0.0;
    for (double h : heights) H += h;
    return H;
  }
  int storeys() const { return static_cast<int>(heights.size()); }
};

struct RigidBodySpec {
  double mass = 0.0;
  double Ixx = 0.0, Iyy = 0.0, Izz = 0.0, Ixy = 0.0, Ixz = 0.0, Iyz = 0.0;  // about its CM
};

// SCOLE (Taylor & Balakrishnan 1984), slug-ft-s. Shuttle body frame: x roll, y pitch, z yaw;
// the mast leaves the shuttle at `mast_root` (shuttle frame, relative to the shuttle CM) along
// body -z; s measured from the root. Roll bending is displacement along y, pitch along x.
struct ScoleSpec {
  double length = 130.0;
  double rho_A = 0.0956;
  double EI_roll = 4.0e7;
  double EI_pitch = 4.0e7;
  double GJ = 4.0e7;
  double rho_I_psi = 0.9089;
  // Damping ratio, dimensionless (docs/theory.md §3.3): square-root (Chen–Russell) damping
  // 2ζ√(ρA·EI) on the bending slope rate relative to the shuttle frame, and Kelvin–Voigt torsion
  // c_ψ = 2ζ√(ρI_ψ·GJ)·2L/π (ratio ζ in the first clamped–free torsion mode).
  double zeta = 0.003;
  // Rotary inertia of the mast cross-section in bending (Rayleigh beam): ρI_b = ρI_ψ/2 per plane,
  // as for any axisymmetric section (polar = twice the bending moment of inertia). The Simbody
  // chain's segments are rigid bodies and always carry it (Ixx + Iyy >= Izz), so a truth refuses
  // `false`; the identifier's FE model can drop it (the Euler–Bernoulli mast of the paper).
  bool bending_rotary_inertia = true;
  RigidBodySpec shuttle{6366.0, 905443.0, 6789100.0, 7086601.0, 0.0, 0.0, 0.0};
  RigidBodySpec reflector{12.42, 4969.0, 4969.0, 9938.0, 0.0, 0.0, 0.0};
  double reflector_rx = 18.75;   // reflector CM offset from the mast tip, shuttle x
  double reflector_ry = -32.5;   // shuttle y
  std::vector<double> mast_root = {0.0, 0.0, 0.0};
  std::vector<double> actuator_locations = {130.0 / 3.0, 260.0 / 3.0};
  double actuator_mass = 0.2;
  // Travel of each proof mass on each of its two sliders, either way from the centre (|q| <= stroke),
  // one value for all actuators, in the scenario's length unit. The truth refuses a run in which a
  // proof mass goes beyond it (docs/truth-guards.md). 0.5 ft (±6 in) is a reasoned default, not a
  // sourced figure: the SCOLE design challenge gives the actuators' stations and mass but no
  // travel, and linear proof-mass actuators for structural control move a few inches to about a
  // foot either way. A scenario whose actuators are passive states more (the built-ins do): its
  // free proof masses stay put while the structure's rigid motion carries the mast past them.
  double actuator_stroke = 0.5;
  // Proof-mass actuator hardware (docs/theory.md §3.7), the same for every actuator and both
  // sliders: a centering spring [lb/ft] and a damper [lb·s/ft] between the proof mass and the
  // mast. Zero for both is the free slider (an ideal force source on a free mass).
  double actuator_stiffness = 0.0;
  double actuator_damping = 0.0;
  // Servo lag [s] of every actuator (>= 0; 0 = none): the commanded force f_cmd(t) of an
  // `at: actuatorK` input reaches the proof mass as f(t), the output of the first-order lag
  //   τ ḟ + f = f_cmd(t),   f(0) = f_cmd(0).
  // (A command that jumps at t = 0 therefore reaches the mass at once; one that starts later lags.)
  // The Simbody truth models it without an extra state: f_cmd is a known function of time, so f
  // is computed once at setup, by exact exponential integration across a grid on which f_cmd is
  // replaced by quadratics (to ~1e-8 of its amplitude), and evaluated between nodes by the same
  // formula (model/inputs.h, LaggedSignal). The identifier's FE model has no lag and refuses
  // τ > 0: a mismatch study sets it under truth.overrides.scole.
  double actuator_lag = 0.0;
};

// Where on the structure an input acts or a sensor reads, and the unit of its signal: `at` the
// body ("beam" or "mast", then `location` is the station s; "shuttle", "reflector", "actuatorK"),
// `direction` a unit axis in the shuttle frame ([0,1,0] etc.; beams act and read transversally and
// ignore it).
struct PointSpec {
  std::string name;
  Site at = Site::Beam;
  double location = 0.0;
  std::vector<double> direction = {0.0, 0.0, 0.0};
  std::string unit;
};

// How a data column is conditioned before the identifier uses it (docs/data.md "Conditioning"),
// in the sensor's or input's own unit, after the unit conversion:
//   x' = sign · scale · (x − offset),   then, with detrend, x' less its least-squares line,
// offset: none | mean (the whole record's mean) | {mean_before: T} (the mean of the samples before
// t = T: a transducer's static offset read off the pre-trigger) | a value. scale > 0 is a
// calibration factor, sign −1 a transducer mounted (or wired) the other way round. Applies to
// columns of a data file or table; a run that synthesises its data refuses it.
struct Conditioning {
  enum class Offset { None, Mean, MeanBefore, Value };
  Offset offset = Offset::None;
  double offset_value = 0.0;  // Value: the offset; MeanBefore: T [s]
  double scale = 1.0;
  double sign = 1.0;
  bool detrend = false;
  // An input's force window (docs/data.md §2): Auto keeps an impact's column around its hits and
  // zeroes it elsewhere (the channel's noise before and after a hit is no force); None leaves the
  // column as it is; Span keeps [window_from, window_to] s. Sensors have none.
  enum class Window { Auto, None, Span };
  Window window = Window::Auto;
  double window_from = 0.0, window_to = 0.0;
  // The values change: an offset, a factor or a trend.
  bool transforms() const { return offset != Offset::None || scale != 1.0 || sign != 1.0 || detrend; }
  bool stated() const { return transforms() || window != Window::Auto; }
};

// A point input, a force or a moment. At "actuatorK" (K = 1, 2) it is the proof mass's commanded
// force along its slider.
struct InputSpec : PointSpec {
  InputKind kind = InputKind::Force;
  // A beam's force on an attachment's lumped mass (its own degree of freedom, docs/theory.md §2.5:
  // a shaker's drive on its armature) in place of a station: the attachment's name, "" for none.
  std::string attachment;
  // With a data file (scole-identify --data): "auto" drives the input by the file's column of the
  // same name when there is one, else by `signal`; "data" requires the column (an error if it is
  // missing); "scenario" always uses `signal`. The truth always uses `signal`.
  SignalFrom signal_from = SignalFrom::Auto;
  // How a column that drives the input is read between its samples: "linear" (piecewise linear:
  // a jump stays within its sample), "cubic" (the 4-point Lagrange cubic through the neighbouring
  // samples: midway between samples a smooth force's harmonic at f keeps 1 − (π f Δt)²/2 of its
  // amplitude read linearly, 1 − 3 (2π f Δt)⁴/128 read cubically: at 20 samples a period 1.2 %
  // against 0.05 %), "auto" (linear for a column that jumps — a step, or an impact over a few
  // samples — cubic otherwise).
  Interpolation interpolation = Interpolation::Auto;
  Signal signal;
  // The data column that drives it (free text, e.g. "Hammer [N]"); "" = the column named `name`.
  std::string column;
  // The column's unit, in place of what its header or file states ("" = theirs).
  std::string column_unit;
  Conditioning conditioning;
};

// A sensor. kind: one of the sensor kinds (io/types.h, kSensorKinds: what each reads and which
// structures read it; a kind's own fields, such as a strain gauge's offset, are in `fields`).
// For beams: transverse displacement w(s) or slope w_s(s) at `location`; a strain gauge (beams
// only) reads the axial surface strain ε = −offset · w_ss(s), `offset` the gauge's signed distance
// from the neutral axis (+ on the side w points to: a positive curvature w_ss shortens it),
// dimensionless (docs/theory.md §3.5). For SCOLE: the mast station at `location` (or the
// reflector), measured in the shuttle frame along `direction`.
struct SensorSpec : PointSpec {
  SensorKind kind = SensorKind::Displacement;
  double noise_std = 0.0;
  // The numbers its kind declares besides the common fields (types.h, SensorKindTraits::fields),
  // by name, e.g. a strain gauge's "offset"; empty for the kinds that declare none.
  std::map<std::string, double> fields;
  // The value of a field its kind declares (std::out_of_range if the sensor has none by that name).
  double field(const std::string& name) const { return fields.at(name); }
  // The sensor's own error in the truth, in its unit: the truth writes
  //   y(t) = y_ideal(t) + bias + drift·t + noise,
  // bias a constant offset, drift a rate [unit/s]. Set only under truth.overrides.sensors (the
  // identifier models neither; the main sensors section refuses them), so both are 0 in the
  // scenario the identifier reads.
  double bias = 0.0;
  double drift = 0.0;
  // The data column it reads (free text, e.g. "Acc1 @0.30m [g]"); "" = the column named `name`.
  // A column's values are converted from the column's unit (its header's bracketed suffix, its
  // UFF record, or column_unit) into `unit` (or the unit system's) with UDUNITS-2 (io/units.h).
  std::string column;
  std::string column_unit;
  Conditioning conditioning;
};

struct SimulationSpec {
  double duration = 10.0;
  double sample_interval = 0.01;
  // The record holds the samples at t >= record_start only (s): the structure is simulated from
  // rest at t = 0, and what happened before is not in the record (a record started mid-motion).
  double record_start = 0.0;
  unsigned seed = 1;
};

// A quantity the identifier's model holds fixed but knows only to a tolerance
// (identification.uncertain: {path: tolerance}); it widens the reported uncertainty interval by its
// consider term (docs/theory.md §8.2). `field` is a path of io/scenario_fields.h. A number is a ± tolerance
// in the field's unit; a switch (scole.bending_rotary_inertia) names the alternative model form.
struct UncertainSpec {
  std::string field;
  double tolerance = 0.0;      // numbers: ± this
  bool is_switch = false;
  bool alternative = false;    // switches: the other setting to consider
};

// identification.frf (docs/theory.md §6.10, docs/scenario.md): how frequency responses are made from
// a time record, and how a UFF file's FRFs are read.
struct FrfSpec {
  // auto: lines when the input's scenario signal is made of sines (its lines known), else h1.
  FrfEstimatorKind estimator = FrfEstimatorKind::Auto;
  double segment = 0.0;   // Welch segment [s]; 0 = automatic (eight segments, a power of two samples)
  double overlap = 0.5;   // Welch overlap, [0, 1)
  FrfWindowKind window = FrfWindowKind::Hann;
  std::vector<double> lines;  // Hz, for the lines estimator; empty = the input signal's sine frequencies
  // impact: the exponential window e^{-decay (t - t_0)} on the force and every response [1/s];
  // < 0 = automatic (ln 100 / the record's length: 1 % at its end), 0 = none.
  double decay = -1.0;
  // A UFF file of FRFs: scenario sensor ← "<node><sign><axis>" of its response, the excitation's
  // "<node><sign><axis>" ("" = the one reference of the file), and how well the values are known
  // when the file does not say (relative_std of |H|, or averages with the file's coherence).
  std::vector<std::pair<std::string, std::string>> stations;
  std::string reference;
  double relative_std = 0.0;
  int averages = 0;
};

struct IdentificationSpec {
  // "physical": the structure's quantities by name (beam: rho_A, EI, EI_k (k = 1..N), zeta, c_kv;
  //             SCOLE: rho_A, EI, EI_roll, EI_pitch, GJ, rho_I_psi, zeta, m_reflector).
  // "paper":    the beam equation divided by rho_A: q1 = EI/rho_A, q2 = 1/rho_A,
  //             q3 = c_kv/rho_A (then q1_k on sections).
  std::string parameterization = "physical";
  std::vector<std::string> estimate;
  // Starting point: physical values (rho_A, EI, zeta, c_kv, EI_k) and/or parameter values by name.
  std::map<std::string, double> initial;
  int elements = 10;          // identifier mesh
  int sections = 0;           // equal sections carrying EI_k in the identifier (0 = the beam's own)
  int data_elements = 0;      // mesh that synthesises data; 0 = 2 x elements (at least 2x)
  Method method = Method::Auto;  // auto | gauss-newton | gauss-newton-krylov | lbfgs | steepest-descent
  int max_iterations = 50;
  double gradient_tolerance = 1e-9;  // on the scaled gradient
  double step_tolerance = 1e-5;      // relative parameter change (GN converges quadratically below it)
  // Gauss–Newton horizon continuation: fit the data up to the time where the relative
  // mean-square misfit per sensor reaches this bound, lengthening the horizon as the fit improves
  // (identify/include/scoleid/identify/inverse/optimizers.h); 0 = fit the whole record from the start.
  double continuation_misfit = 0.05;
  std::vector<double> steepest_weights;  // paper's w_i; empty = automatic
  // The frequency band [f_lo, f_hi] in Hz the fit compares model and data in (empty = the whole
  // record): inputs and outputs pass the same causal Butterworth band-pass
  // (identify/include/scoleid/identify/inverse/band_filter.h); f_lo = 0: low-pass only.
  std::vector<double> band;
  // `band: auto` (the default, with no band stated): a measured record's band is chosen from its
  // spectral peaks and its sampling (docs/data.md §2.4); a synthetic record is fitted whole.
  // `band: none`: the whole record. A stated band always wins.
  enum class BandMode { Auto, None };
  BandMode band_mode = BandMode::Auto;
  Integrator integrator = Integrator::Esdirk;  // esdirk (fixed step, L-stable) | esdirk-arkode (the same through ARKODE) | bdf (adaptive CVODES)
  double time_step = 0.0;             // esdirk step; 0 = automatic (step_rule)
  // The automatic step's rule (docs/theory.md §5.2): "parameters" resolves flexible modes up to
  // min(P + 2, modes below Nyquist) (P the estimated parameters; the default), "data" the modes
  // the inputs visibly excite at the sensors (K_data, below Nyquist) whatever P: a step independent
  // of the number of parameters, shorter for few parameters on rich data.
  StepRule step_rule = StepRule::Parameters;
  double rtol = 1e-8;                 // bdf tolerance (and Newton tolerance)
  std::vector<UncertainSpec> uncertain;  // declared tolerances of fixed quantities (consider terms)
  // The model-form error the data are expected to carry, as a fraction of each sensor's RMS
  // signal: the fit test's allowance beyond noise and discretisation (identify/inverse/fit_test.h).
  // < 0 = automatic: 0 for data the scenario synthesises from its own model (no truth.overrides),
  // 0.01 for anything else (a data file, a truth with overrides).
  double model_error = -1.0;
  // Further attempts when the fit does not explain the data (the other start of sectional
  // parameters, a slower horizon continuation); 0 = report the first attempt as it is.
  int restarts = 2;
  // How the first attempt starts (docs/theory.md §7.6): "plain" from the initial values,
  // "coarse-to-fine" from the ladder over sectional parameters, "auto" = the ladder for a family of
  // more than 16 sections, plain otherwise.
  Start start = Start::Auto;
  // The identifier's model (docs/theory.md §3.8): "linear" (small motions, the default) or
  // "nonlinear" (SCOLE only: finite shuttle rotation, the mast's deflection in the shuttle's
  // rotating frame; for slews).
  Model model = Model::Linear;
  // Smoothness prior on the logarithm of sectional parameters (EI_1 … EI_N and the like, neighbours
  // tied by ½ β Σ (log q_{j+1} − log q_j)²; method gauss-newton or gauss-newton-krylov): β >= 0, 0 = off (the
  // default), < 0 ("discrepancy" in YAML) = β chosen by the discrepancy principle from the stated
  // sensor noise (docs/theory.md §7.8).
  double smoothness = 0.0;
  // The structure's state at the record's first sample (docs/theory.md §6.9): "rest" (the default)
  // or "estimate" — the initial displacement and velocity in the identifier's lowest modes at the
  // start values, eliminated at every step by least squares (a record that begins already
  // vibrating: a tap test whose pre-trigger rings, a record started mid-motion).
  InitialState initial_state = InitialState::Rest;
  // The modes that carry the estimated initial state: 0 = automatic (those below the highest
  // frequency the data contain, at most kMaxInitialStateModes).
  int initial_state_modes = 0;
  // What the fit compares (docs/theory.md §6.10): "time" (the record itself, the default) or
  // "frequency" — frequency response functions of the one input to every sensor, made from the
  // record (identification.frf) or read from a UFF file of FRFs (--data), fitted line by line.
  Domain domain = Domain::Time;
  FrfSpec frf;
};
inline constexpr int kMaxInitialStateModes = 24;

// How a data file is read (docs/data.md): the time column by name ("" = the first column), and its
// unit when the header does not state one ("" = seconds).
struct DataSpec {
  std::string time_column;
  std::string time_unit;
  // The DAQ's sample rate [Hz] (0 = not stated): the times become t0 + k/rate (io/time_grid.h).
  double sample_rate = 0.0;
  // The fit window [t_start, t_end] in s (empty: the whole record): the samples fitted; the model
  // starts at the first of them (identify/run/problem.cpp fit_window).
  std::vector<double> window;
};

struct TruthModelSpec {
  int segments = 40;
  std::string integrator = "auto";
  // Local error per step (the phase error per step on the fundamental mode for the implicit
  // rules). 1e-9: the trapezoidal rule keeps the energy drift of a deformed undamped chain below
  // 1e-6 over 50 periods from here (model/trapezoidal.h); Gauss–Legendre, auto's choice from rest,
  // is then bounded by the samples on the SCOLE records (model/gauss_legendre.h).
  double accuracy = 1e-9;
  double output_interval = 0.0;   // 0 = simulation.sample_interval
  // The acquisition's anti-alias filter (Hz; 0 = none, the default): every channel, inputs and
  // sensors alike, passes an 8-pole Butterworth low-pass at this corner before it is sampled, as a
  // DAQ's does; the truth samples 8 times faster inside, filters, keeps every 8th sample, and adds
  // the sensors' noise after (ADC noise, white at the stated level). Must lie below the output's
  // Nyquist frequency. The identifier never reads it: a filter applied alike to inputs and outputs
  // commutes with a linear model (docs/theory.md §9, "Acquisition").
  double anti_alias_hz = 0.0;
  // truth.overrides as YAML text ("" = none): a partial beam: or scole: section applied on top of
  // the scenario's structure, and `sensors:`, partial sensor entries identified by name (location,
  // direction, bias, drift), applied on top of the scenario's sensors, for the truth only
  // (truth_scenario). The identifier never reads it.
  std::string overrides;
  std::string overrides_source;   // where it was read, for messages
  // A large-motion study (e.g. scole-slew): the truth does not refuse rotations beyond the
  // small-rotation bound of the identifier's linear model (docs/truth-guards.md).
  bool large_motion = false;
};

struct Scenario {
  std::string name;
  std::string description;
  std::string source;       // file path or "built-in scenario 'NAME'", used in messages
  Structure structure = Structure::Beam;
  // The unit system the numbers are in (`units: SI | slug-ft-s`); None: not stated (sensor and
  // input units are then checked for their dimension only).
  units::System units = units::System::None;
  BeamSpec beam;
  ScoleSpec scole;
  FrameSpec frame;
  std::vector<InputSpec> inputs;
  std::vector<SensorSpec> sensors;
  SimulationSpec simulation;
  IdentificationSpec identification;
  DataSpec data;
  TruthModelSpec truth;
};

// The scenario as the truth sees it: truth.overrides applied to its structure section and its
// sensors.
Scenario truth_scenario(const Scenario& scenario);
// Whether truth.overrides changes any structure or sensor field.
bool has_truth_overrides(const Scenario& scenario);

// Sensors that sample the structure's mode shapes at 2·count + 2 stations along its length (the
// cross-check's MAC, crosscheck/modes.h): a beam's deflection; the mast's two deflections and its
// torsion, the rotation's row scaled by the length so that it weighs like a deflection.
struct ShapeSensor {
  SensorSpec spec;
  double scale = 1.0;
};
std::vector<ShapeSensor> shape_sensors(const Scenario& sc, int count);

// NAME (a built-in) or a path to a YAML file. Throws InputError.
Scenario load_scenario(const std::string& name_or_file);
// Parses YAML text; `source` names it in error messages. Throws InputError.
Scenario parse_scenario(const std::string& yaml_text, const std::string& source);

std::vector<std::string> builtin_scenario_names();
std::string builtin_scenario_yaml(const std::string& name);  // "" if unknown
// The same, or InputError naming the built-ins (--print-scenario).
std::string builtin_scenario_text(const std::string& name);
// One line per built-in: name and description (--list-scenarios).
std::string builtin_scenario_listing();
std::string builtin_scenario_description(const std::string& name);

// Every field, defaults included: the settings a run actually used, echoed into its outputs.
nlohmann::json to_json(const Scenario& s);

}  // namespace scoleid::io
