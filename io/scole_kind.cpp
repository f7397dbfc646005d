// SCOLE's table (structure_kinds.h): shuttle, mast, reflector and proof-mass actuators
// (docs/theory.md §3).
#include "structure_kinds.h"

#include <cmath>

#include "scoleid/io/error.h"
#include "scoleid/io/number.h"

namespace scoleid::io {

namespace {

std::vector<std::pair<std::string, double*>> numbers(Scenario& sc) {
  auto& s = sc.scole;
  std::vector<std::pair<std::string, double*>> v = {
      {"scole.length", &s.length},           {"scole.rho_A", &s.rho_A},
      {"scole.EI_roll", &s.EI_roll},         {"scole.EI_pitch", &s.EI_pitch},
      {"scole.GJ", &s.GJ},                   {"scole.rho_I_psi", &s.rho_I_psi},
      {"scole.zeta", &s.zeta},               {"scole.reflector_rx", &s.reflector_rx},
      {"scole.reflector_ry", &s.reflector_ry}, {"scole.actuator_mass", &s.actuator_mass},
      {"scole.actuator_stiffness", &s.actuator_stiffness}, {"scole.actuator_damping", &s.actuator_damping}};
  for (auto [name, body] : {std::pair<const char*, RigidBodySpec*>{"shuttle", &s.shuttle}, {"reflector", &s.reflector}}) {
    const std::string p = std::string("scole.") + name + ".";
    v.insert(v.end(), {{p + "mass", &body->mass}, {p + "Ixx", &body->Ixx}, {p + "Iyy", &body->Iyy}, {p + "Izz", &body->Izz},
                       {p + "Ixy", &body->Ixy}, {p + "Ixz", &body->Ixz}, {p + "Iyz", &body->Iyz}});
  }
  return v;
}

std::vector<ParameterRow> parameters(const Scenario&) {
  return {{{"rho_A", "mast mass per unit length", "mass/length"}, [](Scenario& s) -> double& { return s.scole.rho_A; }},
          {{"EI_roll", "mast bending stiffness, roll plane (displacement along shuttle y)", "force·length²"},
           [](Scenario& s) -> double& { return s.scole.EI_roll; }},
          {{"EI_pitch", "mast bending stiffness, pitch plane (displacement along shuttle x)", "force·length²"},
           [](Scenario& s) -> double& { return s.scole.EI_pitch; }},
          {{"GJ", "mast torsional stiffness", "force·length²"}, [](Scenario& s) -> double& { return s.scole.GJ; }},
          {{"rho_I_psi", "mast torsional inertia per unit length", "mass·length"},
           [](Scenario& s) -> double& { return s.scole.rho_I_psi; }},
          {{"zeta", "mast damping ratio ζ (Chen–Russell bending, Kelvin–Voigt torsion; docs/theory.md §3.3)",
            "dimensionless"},
           [](Scenario& s) -> double& { return s.scole.zeta; }},
          {{"m_reflector", "reflector mass", "mass"}, [](Scenario& s) -> double& { return s.scole.reflector.mass; }},
          {{"k_actuator", "proof-mass actuator centering spring (docs/theory.md §3.7)", "force/length"},
           [](Scenario& s) -> double& { return s.scole.actuator_stiffness; }},
          {{"c_actuator", "proof-mass actuator damper (docs/theory.md §3.7)", "force·time/length"},
           [](Scenario& s) -> double& { return s.scole.actuator_damping; }}};
}

// "EI" sets both bending planes.
void set_stiffness(Scenario& sc, const std::map<std::string, double>& values) {
  if (const auto it = values.find("EI"); it != values.end()) sc.scole.EI_roll = sc.scole.EI_pitch = it->second;
}

// The mast's two deflections and its torsion at 2·count + 2 stations up to the tip, the
// rotation's row scaled by the length.
std::vector<ShapeSensor> shape_stations(const Scenario& sc, int count) {
  std::vector<ShapeSensor> out;
  const int m = 2 * count + 2;
  const double L = sc.scole.length;
  for (int k = 1; k <= m; ++k) {
    const double s = L * k / m;
    const std::string tag = "s" + std::to_string(k);
    out.push_back(shape_sensor(tag + "_x", Site::Mast, SensorKind::Displacement, s, {1, 0, 0}, 1.0));
    out.push_back(shape_sensor(tag + "_y", Site::Mast, SensorKind::Displacement, s, {0, 1, 0}, 1.0));
    out.push_back(shape_sensor(tag + "_rz", Site::Mast, SensorKind::Rotation, s, {0, 0, 1}, L));
  }
  return out;
}

std::string vec_text(const std::vector<double>& v) {
  return "[" + format_value(v[0]) + ", " + format_value(v[1]) + ", " + format_value(v[2]) + "]";
}
bool given(const std::vector<double>& d) { return d.size() == 3 && d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > 0.0; }

// Inputs on the shuttle, the mast, the reflector or a proof-mass actuator (a force in the
// actuator plane); sensors on the shuttle, the mast or the reflector, each along a given
// direction; a line of sight starts at the mast's root, so it needs a point away from it; the
// mast is uniform (no stiffness sections).
void check(const Scenario& sc) {
  const std::size_t nact = sc.scole.actuator_locations.size();
  for (std::size_t i = 0; i < sc.inputs.size(); ++i) {
    const InputSpec& in = sc.inputs[i];
    const std::string f = "inputs[" + std::to_string(i) + "]";
    if (const int k = actuator_index(in.at); k >= 0) {
      if (static_cast<std::size_t>(k) >= nact)
        fail_field(sc.source, f + ".at", "names an actuator the configuration does not have", quoted(in.at));
      if (in.kind != InputKind::Force) fail_field(sc.source, f + ".kind", "must be 'force' for a proof-mass actuator", quoted(in.kind));
      if (!given(in.direction) || std::abs(in.direction[2]) > 1e-12)
        fail_field(sc.source, f + ".direction", "must lie in the actuator plane (x, y)", vec_text(in.direction));
      continue;
    }
    if (in.at != Site::Shuttle && in.at != Site::Mast && in.at != Site::Reflector)
      fail_field(sc.source, f + ".at", "must be shuttle, reflector, mast, actuator1 or actuator2 for a scole structure",
                 quoted(in.at));
    if (!given(in.direction)) fail_field(sc.source, f + ".direction", "must be given (x, y, z or a 3-vector)", "none");
  }
  for (std::size_t k = 0; k < sc.sensors.size(); ++k) {
    const SensorSpec& se = sc.sensors[k];
    const std::string f = "sensors[" + std::to_string(k) + "]";
    if (se.at != Site::Shuttle && se.at != Site::Mast && se.at != Site::Reflector)
      fail_field(sc.source, f + ".at", "must be mast, reflector or shuttle for a scole structure", quoted(se.at));
    if (!given(se.direction)) fail_field(sc.source, f + ".direction", "must be given (x, y, z or a 3-vector)", "none");
    if (se.kind == SensorKind::LineOfSight && se.at == Site::Shuttle)
      fail_field(sc.source, f + ".kind", "is defined for the mast and the reflector, not the shuttle", "'line_of_sight'");
    if (se.kind == SensorKind::LineOfSight && se.at == Site::Mast && !(se.location > 0.0))
      fail_field(sc.source, f + ".location", "must be > 0 for a line of sight (the line starts at the root)",
                 format_value(se.location));
  }
  if (sc.identification.sections > 1)
    fail_field(sc.source, "identification.sections", "must be 0 or 1 for a scole structure (uniform mast)",
               std::to_string(sc.identification.sections));
}

}  // namespace

const KindTable& scole_kind() {
  static const KindTable t{
      [](const Scenario& sc) { return sc.scole.length; },
      numbers,
      {"scole.reflector_rx", "scole.reflector_ry", "scole.shuttle.Ixy", "scole.shuttle.Ixz", "scole.shuttle.Iyz",
       "scole.reflector.Ixy", "scole.reflector.Ixz", "scole.reflector.Iyz"},
      [](Scenario& sc) {
        return std::vector<std::pair<std::string, bool*>>{{"scole.bending_rotary_inertia", &sc.scole.bending_rotary_inertia}};
      },
      parameters,
      set_stiffness,
      shape_stations,
      check,
      [](Scenario& sc) {
        return std::vector<std::pair<std::string, double*>>{{"scole.actuator_stroke", &sc.scole.actuator_stroke},
                                                            {"scole.actuator_lag", &sc.scole.actuator_lag}};
      }};
  return t;
}

}  // namespace scoleid::io
