#include "scoleid/identify/door/scenario_door.h"

#include <stdexcept>

#include "scoleid/io/error.h"
#include "scoleid/io/scenario_fields.h"
#include "scoleid/io/validation.h"

namespace scoleid::identify {

namespace {
bool valid(const io::Scenario& sc) {
  try {
    io::validate_scenario(sc);
    return true;
  } catch (const io::InputError&) {
    return false;
  }
}
}  // namespace

UncertainSides uncertain_sides(const io::Scenario& sc, const io::UncertainSpec& u) {
  if (u.is_switch) return {true, false};
  // The moved structure's validity (its declarations are the original's, checked by the caller).
  io::Scenario hi = sc;
  hi.identification.uncertain.clear();
  io::Scenario lo = hi;
  double* vh = io::numeric_field(hi, u.field);
  double* vl = io::numeric_field(lo, u.field);
  if (!vh || !vl) throw std::logic_error("uncertain_sides: '" + u.field + "' is no numeric field (io::validate_scenario refuses it)");
  const double value = *vh;
  *vh += u.tolerance;
  *vl -= u.tolerance;
  // A quantity that cannot be negative (a stiffness, a mass) is not moved through zero.
  const bool lo_sign = io::signed_field(u.field) || (value > 0 ? *vl > 0 : *vl >= 0);
  return {valid(hi), lo_sign && valid(lo)};
}

void check_scenario(const io::Scenario& sc) {
  io::validate_scenario(sc);
  // The actuator force enters the finite-element equations as commanded: there is no servo
  // state to lag it (a lag is the truth's, truth.overrides.scole.actuator_lag).
  if (sc.structure == io::Structure::Scole && sc.scole.actuator_lag > 0)
    io::fail_field(sc.source, "scole.actuator_lag",
                   "must be 0: the finite-element model has no servo lag: set it under truth.overrides.scole to study the "
                   "mismatch",
                   io::format_value(sc.scole.actuator_lag));
  for (const auto& u : sc.identification.uncertain) {
    const UncertainSides s = uncertain_sides(sc, u);
    if (!s.high && !s.low)
      io::fail_field(sc.source, "identification.uncertain." + u.field, "moves the scenario out of its valid range on both sides",
                     io::format_value(u.tolerance));
  }
  const auto& id = sc.identification;
  if (id.initial_state == io::InitialState::Estimate) {
    if (id.integrator != io::Integrator::Esdirk)
      io::fail_field(sc.source, "identification.integrator",
                     "must be esdirk with initial_state: estimate (its tangents carry the initial state's directions)",
                     io::quoted(id.integrator));
    if (id.method == io::Method::GaussNewtonKrylov)
      io::fail_field(sc.source, "identification.method",
                     "cannot be gauss-newton-krylov with initial_state: estimate (the initial state is profiled out of the "
                     "explicit Gauss-Newton matrix)",
                     "'gauss-newton-krylov'");
  }
  if (id.domain == io::Domain::Frequency) {
    if (sc.inputs.size() != 1)
      io::fail_field(sc.source, "inputs",
                     "must hold exactly one input with identification.domain: frequency (FRFs are per unit of one input)",
                     std::to_string(sc.inputs.size()) + " inputs");
  }
  if (sc.sensors.empty()) io::fail_field(sc.source, "sensors", "must list at least one sensor", "none");
  if (sc.inputs.empty() && sc.identification.initial_state != io::InitialState::Estimate)
    io::fail_field(sc.source, "inputs",
                   "must list at least one input (a record with none, a free decay, needs identification.initial_state: estimate)",
                   "none");
}

void check_synthesis(const io::Scenario& sc) {
  const auto& id = sc.identification;
  if (sc.inputs.empty())
    io::fail_field(sc.source, "inputs",
                   "is empty and this run synthesises its data: from rest with no input nothing moves (a free decay's record "
                   "comes from a data file, --data)",
                   "[]");
  // Conditioning is for a data column; synthetic data have none to condition.
  for (std::size_t i = 0; i < sc.inputs.size(); ++i)
    if (sc.inputs[i].conditioning.stated())
      io::fail_field(sc.source, "inputs[" + std::to_string(i) + "].conditioning",
                     "conditions a data column, and this run synthesises its data (give a data file)", "'" + sc.inputs[i].name + "'");
  for (std::size_t j = 0; j < sc.sensors.size(); ++j)
    if (sc.sensors[j].conditioning.stated())
      io::fail_field(sc.source, "sensors[" + std::to_string(j) + "].conditioning",
                     "conditions a data column, and this run synthesises its data (give a data file)", "'" + sc.sensors[j].name + "'");
  const int data_elements = id.data_elements > 0 ? id.data_elements : 2 * id.elements;
  if (data_elements < 2 * id.elements)
    io::fail_field(sc.source, "identification.data_elements",
                   "must be at least 2x identification.elements (" + std::to_string(2 * id.elements) + ")",
                   std::to_string(data_elements));
  if (id.model == io::Model::Nonlinear && sc.simulation.record_start > 0)
    io::fail_field(sc.source, "simulation.record_start", "is not available to the nonlinear model's synthesis (model: nonlinear)",
                   io::format_value(sc.simulation.record_start));
}

void check_parameters(const FEStructure& st, const io::Scenario& sc) {
  const PhysicalParameterization probe(st.parameter_space(sc), sc.identification);
  if (const auto& r = probe.refusal()) io::fail_field(sc.source, r->field, r->what, r->value);
}

void check_identification(const io::Scenario& sc) {
  check_scenario(sc);
  check_parameters(*make_structure(sc, sc.identification.elements), sc);
}

void check_modal_data(const io::ModalData& d, const io::Scenario& sc) {
  io::validate_modal_data(d);
  const std::string src = d.source.empty() ? std::string("modal data") : d.source;
  for (const std::string& name : d.stations) {
    const io::SensorSpec* found = nullptr;
    for (const auto& s : sc.sensors)
      if (s.name == name) found = &s;
    if (!found || io::derivative_order(found->kind) != 0)
      io::fail_field(src, "column '" + name + "'", "is not a sensor of the scenario read on the displacement (" + sc.source + ")",
                     "'" + name + "'" + (found ? " (its kind is " + std::string(io::to_string(found->kind)) + ")" : std::string(" (no such sensor)")));
  }
}

}  // namespace scoleid::identify
