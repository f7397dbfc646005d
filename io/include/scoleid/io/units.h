#pragma once
// Physical units of data columns, sensors and inputs, converted with UDUNITS-2 (docs/data.md).
//
// A unit is text UDUNITS-2 parses ("m", "mm", "in", "ft/s^2", "lbf", "N m", "µm", "degree"),
// read against the quantity it belongs to, because the symbols engineers write are ambiguous
// outside their context:
//   g      standard gravity (9.80665 m/s²) where an acceleration is meant (UDUNITS reads gram);
//   lb     pound-force where a force or moment is meant (UDUNITS reads pound-mass);
//   deg    arc degree;  µε, με, ue, microstrain  1e-6 (strain);  ε, strain  1.
// Whole labels as DAQ software writes them are read too, in any case (LabVIEW's Y_Unit_Label):
//   Newtons N, Kilonewtons kN, Pounds/Pound/lbs lbf (a force), Meters/Metres m, Millimeters mm,
//   Inches in, Feet ft, Seconds/sec s, Gs/g's standard gravity (an acceleration), Degrees degree,
//   Radians rad.
// A conversion is affine, value_to = scale · value_from + offset (offset is 0 for every unit
// above; temperatures are not data this product reads), with UDUNITS-2's own factors.
//
// A scenario may name its unit system (`units: SI | slug-ft-s`); every declared sensor or input
// unit must then be that system's unit for its quantity (a conversion of scale 1), so a label can
// never disagree with the numbers the model computes in.
#include <optional>
#include <string>

namespace scoleid::io::units {

// What a sensor reads or an input applies, as a physical dimension.
enum class Quantity { Length, Angle, Velocity, Acceleration, Strain, Force, Moment, Time };

// The quantity's name for messages ("acceleration").
const char* quantity_name(Quantity q);
// The quantity of a sensor kind (displacement, rotation, velocity, acceleration, line_of_sight,
// strain) or input kind (force, moment); nullopt for anything else.
std::optional<Quantity> quantity_of_kind(const std::string& kind);

// A named unit system of a scenario. None: the scenario states none (units are labels checked
// only for their dimension).
enum class System { None, SI, SlugFtS };
// "SI" / "slug-ft-s"; parse returns nullopt for other names.
const char* system_name(System s);
std::optional<System> parse_system(const std::string& name);
// The system's unit of a quantity ("m/s^2", "ft/s^2", "lbf", ...).
std::string system_unit(System s, Quantity q);

struct Conversion {
  std::string from, to;  // as written
  double scale = 1.0;
  double offset = 0.0;
  double apply(double v) const { return scale * v + offset; }
  bool identity() const { return scale == 1.0 && offset == 0.0; }
};

// Why `unit` is not a unit of quantity q ("not a unit UDUNITS-2 knows" / "is not a length");
// nullopt when it is one.
std::optional<std::string> problem_with(const std::string& unit, Quantity q);

// The conversion of values of quantity q from unit `from` into unit `to`. Throws
// std::invalid_argument with the reason (unknown unit, or the two dimensions), which the caller
// prefixes with the file and column it concerns.
Conversion conversion(const std::string& from, const std::string& to, Quantity q);

// The unit in a column header's suffix: "Acc1 @0.30m [g]" → "g" (square brackets: always a unit),
// "Time (ms)" → "ms" (parentheses: only when their text is a unit UDUNITS-2 knows, so
// "Acc (tip)" has none); "" when the header ends in neither.
std::string bracketed_unit(const std::string& header);

}  // namespace scoleid::io::units
