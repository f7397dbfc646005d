#include "scoleid/io/structure_parameters.h"

#include <functional>

namespace scoleid::io {

namespace {

struct Row {
  ParameterInfo info;
  std::function<double&(Scenario&)> ref;
};

std::vector<Row> rows(const Scenario& sc) {
  std::vector<Row> r;
  if (sc.structure == Structure::Scole) {
    r = {{{"rho_A", "mast mass per unit length", "mass/length"}, [](Scenario& s) -> double& { return s.scole.rho_A; }},
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
    return r;
  }
  r = {{{"rho_A", "mass per unit length", "mass/length"}, [](Scenario& s) -> double& { return s.beam.rho_A; }},
       {{"zeta", "square-root (Chen–Russell) damping ratio ζ, d = 2ζ√(ρA·EI) (docs/theory.md §2.2)", "dimensionless"},
        [](Scenario& s) -> double& { return s.beam.zeta; }},
       {{"c_kv", "Kelvin–Voigt (strain-rate) damping coefficient (docs/theory.md §2.2)", "force·length²·time"},
        [](Scenario& s) -> double& { return s.beam.c_kv; }}};
  if (sc.beam.EI.size() == 1) {
    r.push_back({{"EI", "bending stiffness", "force·length²"}, [](Scenario& s) -> double& { return s.beam.EI[0]; }});
  } else {
    for (std::size_t k = 0; k < sc.beam.EI.size(); ++k)
      r.push_back({{"EI_" + std::to_string(k + 1), "bending stiffness of section " + std::to_string(k + 1), "force·length²"},
                   [k](Scenario& s) -> double& { return s.beam.EI[k]; }});
  }
  return r;
}

}  // namespace

std::vector<ParameterInfo> structure_parameter_table(const Scenario& sc) {
  std::vector<ParameterInfo> t;
  for (const auto& r : rows(sc)) t.push_back(r.info);
  return t;
}

std::map<std::string, double> structure_parameters(const Scenario& sc) {
  Scenario copy = sc;
  std::map<std::string, double> p;
  for (const auto& r : rows(sc)) p[r.info.name] = r.ref(copy);
  return p;
}

void set_structure_parameters(Scenario& sc, const std::map<std::string, double>& values) {
  // "EI" for every section / both planes first, so that a sectional or per-plane value wins.
  if (const auto it = values.find("EI"); it != values.end()) {
    if (sc.structure == Structure::Scole) sc.scole.EI_roll = sc.scole.EI_pitch = it->second;
    else sc.beam.EI = {it->second};  // a uniform beam
  }
  if (sc.structure == Structure::Beam) {
    // A truth with its own sections: take them all.
    std::vector<double> sections;
    for (int k = 1; values.count("EI_" + std::to_string(k)); ++k) sections.push_back(values.at("EI_" + std::to_string(k)));
    if (!sections.empty()) sc.beam.EI = sections;
  }
  for (const auto& r : rows(sc)) {
    const auto it = values.find(r.info.name);
    if (it != values.end()) r.ref(sc) = it->second;
  }
}

}  // namespace scoleid::io
