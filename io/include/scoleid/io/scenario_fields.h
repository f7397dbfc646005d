#pragma once
// Scenario quantities by their path ("scole.reflector.mass", "beam.tip_mass",
// "sensors.roll_tip.location", "scole.bending_rotary_inertia"): how identification.uncertain
// names a quantity the model holds fixed but knows only to a tolerance (the consider terms of the
// uncertainty interval, docs/theory.md §8.2).
#include <string>
#include <vector>

#include "scoleid/io/scenario.h"

namespace scoleid::io {

// The number at `path` in `sc`, or nullptr when the path names none.
double* numeric_field(Scenario& sc, const std::string& path);
// Whether the number at `path` may take negative values (offsets and products of inertia); every
// other number must stay >= 0, and > 0 where the scenario requires it (lengths, masses, stiffnesses).
bool signed_field(const std::string& path);
// The switch at `path`, or nullptr.
bool* bool_field(Scenario& sc, const std::string& path);
// Where the truth's number at `path` is set: "truth.overrides.<path>" when truth (the scenario's
// truth_scenario) holds another value there than scenario, else `path` (for messages). Also for
// the numbers only the truth reads (an actuator's stroke), which numeric_field does not offer.
std::string truth_field(const Scenario& scenario, const Scenario& truth, const std::string& path);
// Every path numeric_field and bool_field accept for this scenario (for messages).
std::vector<std::string> field_paths(const Scenario& sc);

}  // namespace scoleid::io
