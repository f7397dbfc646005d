#pragma once
// The closed choices of a scenario and of the programs' options, as types. Strings exist only at
// the edge: the scenario reader, the command lines and the JSON writers convert with the one table
// per type below; everything inside compares enums.
//
//   Structure   structure                           the structure kind (beam | scole | frame)
//   Method      identification.method, --method     the optimiser (identify/inverse/optimizers.h)
//   Start       identification.start                how the first attempt starts (docs/theory.md §7.6)
//   Model       identification.model                the identifier's linear or nonlinear model (§3.8)
//   StepRule    identification.step_rule            the automatic time step's rule (§5.2)
//   Integrator  identification.integrator           the identifier's time stepper (§5)
//   Domain      identification.domain               time records or frequency responses (§6.10)
//   FrfEstimatorKind identification.frf.estimator   how FRFs are made from a time record (§6.10)
//   FrfWindowKind    identification.frf.window      the Welch segments' window
//   SensorKind  sensors[].kind                      what a sensor reads (§3.5, §6.1a)
//   Site        inputs[].at, sensors[].at            the body a sensor or input is on (§3.5, §4)
//   InputKind   inputs[].kind                        what an input applies: a force or a moment
//   SignalFrom  inputs[].signal_from                 what drives an input with a data file (§9)
//   Interpolation inputs[].interpolation             how an input's column is read between samples
//
// Adding a value: one enumerator and one row of its table, here; the reader, --help and the JSON
// writers follow, and a switch over the type that misses it is a compiler warning. A sensor kind
// also has one row of kSensorKinds (what it reads, which structures read it, its own fields).
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "scoleid/io/units.h"

namespace scoleid::io {

enum class Structure { Beam, Scole, Frame };
enum class Method { Auto, GaussNewton, GaussNewtonKrylov, Lbfgs, SteepestDescent };
enum class Start { Auto, Plain, CoarseToFine };
enum class Model { Linear, Nonlinear };
enum class StepRule { Parameters, Data };
enum class Integrator { Esdirk, EsdirkArkode, Bdf };
enum class InitialState { Rest, Estimate };
enum class Domain { Time, Frequency };
enum class FrfEstimatorKind { Auto, H1, H2, Lines, Impact };
enum class FrfWindowKind { Hann, Rectangular };
enum class SensorKind { Displacement, Rotation, Velocity, Acceleration, LineOfSight, Strain, RelativeDisplacement };
enum class Site { Beam, Mast, Shuttle, Reflector, Actuator1, Actuator2, Frame };
enum class InputKind { Force, Moment };
enum class SignalFrom { Auto, Data, Scenario };
enum class Interpolation { Auto, Linear, Cubic };

// Each type's names, in declaration order (the first is the default where a field has one).
template <class E>
struct Names;
template <>
struct Names<Structure> {
  static constexpr std::array<std::pair<Structure, const char*>, 3> rows{
      {{Structure::Beam, "beam"}, {Structure::Scole, "scole"}, {Structure::Frame, "frame"}}};
};
template <>
struct Names<Method> {
  static constexpr std::array<std::pair<Method, const char*>, 5> rows{{{Method::Auto, "auto"},
                                                                      {Method::GaussNewton, "gauss-newton"},
                                                                      {Method::GaussNewtonKrylov, "gauss-newton-krylov"},
                                                                      {Method::Lbfgs, "lbfgs"},
                                                                      {Method::SteepestDescent, "steepest-descent"}}};
};
template <>
struct Names<Start> {
  static constexpr std::array<std::pair<Start, const char*>, 3> rows{
      {{Start::Auto, "auto"}, {Start::Plain, "plain"}, {Start::CoarseToFine, "coarse-to-fine"}}};
};
template <>
struct Names<Model> {
  static constexpr std::array<std::pair<Model, const char*>, 2> rows{{{Model::Linear, "linear"}, {Model::Nonlinear, "nonlinear"}}};
};
template <>
struct Names<InitialState> {
  static constexpr std::array<std::pair<InitialState, const char*>, 2> rows{
      {{InitialState::Rest, "rest"}, {InitialState::Estimate, "estimate"}}};
};
template <>
struct Names<Domain> {
  static constexpr std::array<std::pair<Domain, const char*>, 2> rows{{{Domain::Time, "time"}, {Domain::Frequency, "frequency"}}};
};
template <>
struct Names<FrfEstimatorKind> {
  static constexpr std::array<std::pair<FrfEstimatorKind, const char*>, 5> rows{
      {{FrfEstimatorKind::Auto, "auto"}, {FrfEstimatorKind::H1, "h1"}, {FrfEstimatorKind::H2, "h2"}, {FrfEstimatorKind::Lines, "lines"},
       {FrfEstimatorKind::Impact, "impact"}}};
};
template <>
struct Names<FrfWindowKind> {
  static constexpr std::array<std::pair<FrfWindowKind, const char*>, 2> rows{
      {{FrfWindowKind::Hann, "hann"}, {FrfWindowKind::Rectangular, "rectangular"}}};
};
template <>
struct Names<StepRule> {
  static constexpr std::array<std::pair<StepRule, const char*>, 2> rows{
      {{StepRule::Parameters, "parameters"}, {StepRule::Data, "data"}}};
};

template <>
struct Names<Integrator> {
  static constexpr std::array<std::pair<Integrator, const char*>, 3> rows{
      {{Integrator::Esdirk, "esdirk"}, {Integrator::EsdirkArkode, "esdirk-arkode"}, {Integrator::Bdf, "bdf"}}};
};

template <>
struct Names<SensorKind> {
  static constexpr std::array<std::pair<SensorKind, const char*>, 7> rows{
      {{SensorKind::Displacement, "displacement"},
       {SensorKind::Rotation, "rotation"},
       {SensorKind::Velocity, "velocity"},
       {SensorKind::Acceleration, "acceleration"},
       {SensorKind::LineOfSight, "line_of_sight"},
       {SensorKind::Strain, "strain"},
       {SensorKind::RelativeDisplacement, "relative_displacement"}}};
};

template <>
struct Names<Site> {
  static constexpr std::array<std::pair<Site, const char*>, 7> rows{{{Site::Beam, "beam"},
                                                                    {Site::Mast, "mast"},
                                                                    {Site::Shuttle, "shuttle"},
                                                                    {Site::Reflector, "reflector"},
                                                                    {Site::Actuator1, "actuator1"},
                                                                    {Site::Actuator2, "actuator2"},
                                                                    {Site::Frame, "frame"}}};
};
template <>
struct Names<InputKind> {
  static constexpr std::array<std::pair<InputKind, const char*>, 2> rows{
      {{InputKind::Force, "force"}, {InputKind::Moment, "moment"}}};
};
template <>
struct Names<SignalFrom> {
  static constexpr std::array<std::pair<SignalFrom, const char*>, 3> rows{
      {{SignalFrom::Auto, "auto"}, {SignalFrom::Data, "data"}, {SignalFrom::Scenario, "scenario"}}};
};
template <>
struct Names<Interpolation> {
  static constexpr std::array<std::pair<Interpolation, const char*>, 3> rows{
      {{Interpolation::Auto, "auto"}, {Interpolation::Linear, "linear"}, {Interpolation::Cubic, "cubic"}}};
};

// A site along which a location is measured: the beam or the mast (a station s ∈ [0, L]).
constexpr bool has_station(Site s) { return s == Site::Beam || s == Site::Mast || s == Site::Frame; }
// The proof-mass actuator a site names (0, 1), or -1.
constexpr int actuator_index(Site s) { return s == Site::Actuator1 ? 0 : s == Site::Actuator2 ? 1 : -1; }

// A number a sensor kind needs besides the fields every sensor has (name, at, location,
// direction, unit, noise_std, column): the scenario reader requires it on a sensor of the kind,
// checks it by its rule, keeps it in SensorSpec::fields and refuses it on a sensor of any other
// kind; the JSON writer writes it.
struct SensorField {
  enum class Rule {
    Nonzero,  // a number ≠ 0 (`why` says what a zero would mean)
    Station   // a station on the sensor's site, like `location`, and apart from it
  };
  const char* name = nullptr;  // nullptr: no field
  const char* meaning = nullptr;
  Rule rule = Rule::Nonzero;
  const char* why = nullptr;
};

// What a sensor of each kind reads (docs/theory.md §3.5), one row per kind:
//   order       the time derivative of the structure's motion it reads: 0 (displacement-like),
//               1 (velocity), 2 (acceleration);
//   quantity    the physical quantity of its values (the dimension its unit must have);
//   structures  the structure kinds whose models read it (the scenario reader refuses the rest),
//               a bit per Structure (structures_of);
//   mode_shape  whether its value in a mode is an ordinate of the mode shape the cross-check's
//               modal data hold (a displacement or a rotation of one point);
//   plural      what messages call sensors of the kind;
//   fields      the numbers it needs besides the common ones.
struct SensorKindTraits {
  SensorKind kind;
  int order;
  units::Quantity quantity;
  unsigned structures;
  bool mode_shape;
  const char* plural;
  std::array<SensorField, 2> fields;
};

constexpr unsigned structures_of(Structure s) { return 1u << static_cast<unsigned>(s); }
inline constexpr unsigned kEveryStructure = ~0u;

inline constexpr std::array<SensorKindTraits, 7> kSensorKinds{{
    {SensorKind::Displacement, 0, units::Quantity::Length, kEveryStructure, true, "displacement sensors", {}},
    {SensorKind::Rotation, 0, units::Quantity::Angle, kEveryStructure, true, "rotation sensors", {}},
    {SensorKind::Velocity, 1, units::Quantity::Velocity, kEveryStructure, false, "velocity sensors", {}},
    {SensorKind::Acceleration, 2, units::Quantity::Acceleration, kEveryStructure, false, "accelerometers", {}},
    {SensorKind::LineOfSight,
     0,
     units::Quantity::Angle,
     structures_of(Structure::Scole),
     true,
     "line-of-sight sensors",
     {}},
    // ε = −offset · w_ss: the beam's curvature (docs/theory.md §3.5).
    {SensorKind::Strain,
     0,
     units::Quantity::Strain,
     structures_of(Structure::Beam),
     false,
     "strain gauges",
     {{{"offset", "its distance from the neutral axis", SensorField::Rule::Nonzero,
        "a gauge on the neutral axis reads nothing"}}}},
    // w(location) − w(reference): a transducer between two stations of the beam (§3.5).
    {SensorKind::RelativeDisplacement,
     0,
     units::Quantity::Length,
     structures_of(Structure::Beam),
     false,
     "relative-displacement gauges",
     {{{"reference", "the station its other end is fixed to", SensorField::Rule::Station,
        "a gauge whose two ends meet reads nothing"}}}},
}};

// The row of a sensor kind.
constexpr const SensorKindTraits& sensor_traits(SensorKind k) {
  for (const auto& row : kSensorKinds)
    if (row.kind == k) return row;
  return kSensorKinds[0];  // unreachable: every kind has a row (below)
}

constexpr bool every_sensor_kind_has_its_row() {
  if (kSensorKinds.size() != Names<SensorKind>::rows.size()) return false;
  for (std::size_t i = 0; i < kSensorKinds.size(); ++i)
    if (kSensorKinds[i].kind != Names<SensorKind>::rows[i].first) return false;
  return true;
}
static_assert(every_sensor_kind_has_its_row(), "kSensorKinds: one row per SensorKind, in the order of its names");

// The time derivative of the structure's motion a sensor of this kind reads (traits.order).
constexpr int derivative_order(SensorKind k) { return sensor_traits(k).order; }

// Whether the models of a structure kind read this sensor kind (the scenario reader refuses the
// others).
constexpr bool reads(Structure s, SensorKind k) { return (sensor_traits(k).structures & structures_of(s)) != 0; }

// The name a scenario, a command line and identify.json use.
template <class E, class = decltype(Names<E>::rows)>
const char* to_string(E v) {
  for (const auto& [value, name] : Names<E>::rows)
    if (value == v) return name;
  return "?";
}

// The names of the sensor kinds a structure kind's models read, joined by `sep`.
inline std::string sensor_kinds_read_by(Structure s, const char* sep = "|") {
  std::string out;
  for (const auto& [k, name] : Names<SensorKind>::rows)
    if (reads(s, k)) out += (out.empty() ? "" : sep) + std::string(name);
  return out;
}

// The name in single quotes, as a message shows a field's value: 'moment'.
template <class E, class = decltype(Names<E>::rows)>
std::string quoted(E v) {
  return "'" + std::string(to_string(v)) + "'";
}

// The value of a name (nullopt if it names none): parse<Method>(name).
template <class E>
std::optional<E> parse(std::string_view name) {
  for (const auto& [value, n] : Names<E>::rows)
    if (name == n) return value;
  return std::nullopt;
}

// Every name of the type, in declaration order (for messages and --help).
template <class E>
std::vector<std::string> names() {
  std::vector<std::string> out;
  for (const auto& row : Names<E>::rows) out.emplace_back(row.second);
  return out;
}

// The same joined by `sep` ("auto|gauss-newton|…").
template <class E>
std::string names_joined(const char* sep = "|") {
  std::string out;
  for (const auto& row : Names<E>::rows) out += (out.empty() ? "" : sep) + std::string(row.second);
  return out;
}

}  // namespace scoleid::io
