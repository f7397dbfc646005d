// The beam's table (structure_kinds.h): a planar Euler–Bernoulli beam (docs/theory.md §2).
#include "structure_kinds.h"

namespace scoleid::io {

namespace {

std::vector<std::pair<std::string, double*>> numbers(Scenario& sc) {
  auto& b = sc.beam;
  return {{"beam.length", &b.length}, {"beam.rho_A", &b.rho_A}, {"beam.zeta", &b.zeta}, {"beam.c_kv", &b.c_kv},
          {"beam.tip_mass", &b.tip_mass}, {"beam.tip_inertia", &b.tip_inertia}};
}

std::vector<ParameterRow> parameters(const Scenario& sc) {
  std::vector<ParameterRow> r = {
      {{"rho_A", "mass per unit length", "mass/length"}, [](Scenario& s) -> double& { return s.beam.rho_A; }},
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

// "EI" makes the beam uniform; a truth with its own sections EI_1..EI_N gives them all.
void set_stiffness(Scenario& sc, const std::map<std::string, double>& values) {
  if (const auto it = values.find("EI"); it != values.end()) sc.beam.EI = {it->second};
  std::vector<double> sections;
  for (int k = 1; values.count("EI_" + std::to_string(k)); ++k) sections.push_back(values.at("EI_" + std::to_string(k)));
  if (!sections.empty()) sc.beam.EI = sections;
}

// The deflection at 2·count + 2 interior stations.
std::vector<ShapeSensor> shape_stations(const Scenario& sc, int count) {
  std::vector<ShapeSensor> out;
  const int m = 2 * count + 2;
  const double L = sc.beam.length;
  for (int k = 1; k <= m; ++k)
    out.push_back(shape_sensor("w" + std::to_string(k), Site::Beam, SensorKind::Displacement, L * k / (m + 1), {0, 1, 0}, 1.0));
  return out;
}

}  // namespace

const KindTable& beam_kind() {
  static const KindTable t{[](const Scenario& sc) { return sc.beam.length; },
                           numbers,
                           {},
                           [](Scenario&) { return std::vector<std::pair<std::string, bool*>>{}; },
                           parameters,
                           set_stiffness,
                           shape_stations};
  return t;
}

}  // namespace scoleid::io
