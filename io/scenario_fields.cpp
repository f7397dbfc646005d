#include "scoleid/io/scenario_fields.h"

#include <cstring>
#include <utility>

namespace scoleid::io {

namespace {

std::vector<std::pair<std::string, double*>> numbers(Scenario& sc) {
  std::vector<std::pair<std::string, double*>> v;
  if (sc.structure == Structure::Beam) {
    auto& b = sc.beam;
    v = {{"beam.length", &b.length}, {"beam.rho_A", &b.rho_A}, {"beam.zeta", &b.zeta}, {"beam.c_kv", &b.c_kv},
         {"beam.tip_mass", &b.tip_mass}, {"beam.tip_inertia", &b.tip_inertia}};
  } else {
    auto& s = sc.scole;
    v = {{"scole.length", &s.length},           {"scole.rho_A", &s.rho_A},
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
  }
  for (auto& se : sc.sensors)
    if (has_station(se.at)) v.emplace_back("sensors." + se.name + ".location", &se.location);
  return v;
}

}  // namespace

double* numeric_field(Scenario& sc, const std::string& path) {
  for (auto& [name, ptr] : numbers(sc))
    if (name == path) return ptr;
  return nullptr;
}

bool signed_field(const std::string& path) {
  for (const char* end : {"reflector_rx", "reflector_ry", ".Ixy", ".Ixz", ".Iyz"})
    if (path.size() >= std::strlen(end) && path.compare(path.size() - std::strlen(end), std::string::npos, end) == 0) return true;
  return false;
}

bool* bool_field(Scenario& sc, const std::string& path) {
  if (sc.structure == Structure::Scole && path == "scole.bending_rotary_inertia") return &sc.scole.bending_rotary_inertia;
  return nullptr;
}

std::vector<std::string> field_paths(const Scenario& sc) {
  Scenario copy = sc;
  std::vector<std::string> v;
  for (auto& [name, ptr] : numbers(copy)) v.push_back(name);
  if (sc.structure == Structure::Scole) v.push_back("scole.bending_rotary_inertia");
  return v;
}

}  // namespace scoleid::io
