#pragma once
// The identifier's front door for a scenario (docs/theory.md §10.0): what the identifier refuses
// in a scenario, all checked before any model is built —
//   - io::validate_scenario's checks, shared with the Simbody truth: names, counts and limits,
//     every input's and sensor's site, kind, station and direction one the structure's models
//     read, and the kind's own (io/<kind>_kind.cpp, KindTable::check);
//   - what only the identifier refuses: a SCOLE actuator's servo lag outside truth.overrides (the
//     finite-element model has no servo state), a scenario without sensors, a record without
//     inputs unless its initial state is estimated, an estimated initial state without the
//     ESDIRK integrator or with the Krylov method, a frequency-domain run with other than one
//     input or with declared uncertainties.
// Below the door (fe/, time/, inverse/, run/) a scenario that passed it is taken as valid: what
// would be an input error there is a std::logic_error, a caller that went around the door.
#include "scoleid/identify/fe/structure.h"
#include "scoleid/io/modal_data.h"
#include "scoleid/io/scenario.h"

namespace scoleid::identify {

// io::InputError naming the scenario's source, the field and the value. Besides the above: a
// declared uncertainty (identification.uncertain) must leave a valid scenario on one side at least.
void check_scenario(const io::Scenario& sc);

// A run that synthesises its data from the scenario (no data file): an input to drive it, no
// conditioning (it is a data column's), data_elements at least twice the identifier's elements, no
// record_start with the nonlinear model. io::InputError naming the field.
void check_synthesis(const io::Scenario& sc);

// The named parameters (identification.estimate, .initial, .parameterization) against the
// structure's parameter space: known names, none twice, a group not beside its members, starting
// values > 0 and one value per estimated group. io::InputError naming the field.
void check_parameters(const FEStructure& st, const io::Scenario& sc);

// The whole identification door for a scenario: check_scenario, the FE model on its mesh and
// check_parameters (what a campaign or a suite checks of each scenario before anything runs).
void check_identification(const io::Scenario& sc);

// The sides of a declared uncertainty, the field moved by ± its tolerance, that leave a valid
// scenario (io::validate_scenario: a station still on the structure; a quantity that cannot be
// negative not moved through zero). The consider term is central where both are, one-sided at
// the edge of the valid range (docs/theory.md §8.2). A switch has one side, its alternative.
struct UncertainSides {
  bool high = false, low = false;
};
UncertainSides uncertain_sides(const io::Scenario& sc, const io::UncertainSpec& u);

// Measured modes for the scenario's model: io::validate_modal_data's checks (a shape that does
// not vanish among them) and every station a sensor of the scenario read on the displacement
// (displacement, rotation, strain, relative displacement, line of sight: a mode shape is a
// displacement's). io::InputError naming the data's source, the column and the value.
void check_modal_data(const io::ModalData& d, const io::Scenario& sc);

}  // namespace scoleid::identify
