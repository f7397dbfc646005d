#pragma once
// What each structure kind of a scenario offers the kind-agnostic code of io/: its length, its
// numeric and boolean fields by path (scenario_fields.h), its estimable physical parameters
// (structure_parameters.h) and the stations that sample its mode shapes (scenario.h,
// shape_sensors). One table per kind, in the kind's own file (beam_kind.cpp, scole_kind.cpp);
// a new kind adds its file and one row to kind_table (structure_kinds.cpp). Parsing and writing
// the kind's section of a scenario stay with the schema (scenario.cpp).
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "scoleid/io/scenario.h"
#include "scoleid/io/structure_parameters.h"

namespace scoleid::io {

struct ParameterRow {
  ParameterInfo info;
  std::function<double&(Scenario&)> ref;
};

struct KindTable {
  double (*length)(const Scenario&);
  // The kind's numbers by path ("beam.tip_mass", "scole.reflector.mass"); sensor locations are
  // added by the caller.
  std::vector<std::pair<std::string, double*>> (*numbers)(Scenario&);
  // Paths of numbers that may be negative (offsets, products of inertia).
  std::vector<std::string> signed_paths;
  // The kind's switches by path.
  std::vector<std::pair<std::string, bool*>> (*switches)(Scenario&);
  // The estimable physical parameters (for a beam with N > 1 EI sections, EI_1..EI_N replace EI).
  std::vector<ParameterRow> (*parameters)(const Scenario&);
  // Before the rows are set by name: "EI" for a stiffness in several parts (every section, both
  // bending planes) and, for sections, EI_1..EI_N as a whole profile.
  void (*set_stiffness)(Scenario&, const std::map<std::string, double>&);
  std::vector<ShapeSensor> (*shape_sensors)(const Scenario&, int count);
  // The kind's own checks of a whole scenario (validate_scenario, after the stations and sensor
  // kinds): every input's and sensor's site and direction one its models read, and the
  // identification settings its models have (sections, elements). InputError naming the field.
  void (*check)(const Scenario&);
  // Numbers only the Simbody truth reads (a SCOLE actuator's stroke and servo lag), by path: not
  // field paths of numeric_field (not estimable, not declarable uncertain), but named in the truth's
  // messages (truth_field). nullptr: none.
  std::vector<std::pair<std::string, double*>> (*truth_numbers)(Scenario&) = nullptr;
};

const KindTable& kind_table(Structure kind);  // structure_kinds.cpp
std::vector<const KindTable*> kind_tables();  // every kind's
const KindTable& beam_kind();                 // beam_kind.cpp
const KindTable& scole_kind();                // scole_kind.cpp
const KindTable& frame_kind();                // frame_kind.cpp

// A shape sensor at arc position s (shape_sensors).
ShapeSensor shape_sensor(const std::string& name, Site at, SensorKind kind, double s, std::vector<double> direction,
                         double scale);

}  // namespace scoleid::io
