// The frame's table (structure_kinds.h): a planar frame of storeys, each of identical vertical
// columns between rigid floors (docs/theory.md §2.6). Its arc coordinate is the height on the
// first column.
#include "structure_kinds.h"

#include "scoleid/io/error.h"
#include "scoleid/io/number.h"

namespace scoleid::io {

namespace {

std::vector<std::pair<std::string, double*>> numbers(Scenario& sc) {
  auto& f = sc.frame;
  std::vector<std::pair<std::string, double*>> v = {{"frame.rho_A", &f.rho_A}, {"frame.zeta", &f.zeta}, {"frame.tau", &f.tau}, {"frame.bay", &f.bay}};
  for (std::size_t k = 0; k < f.heights.size(); ++k) {
    const std::string i = "[" + std::to_string(k) + "]";
    v.emplace_back("frame.heights" + i, &f.heights[k]);
    if (k < f.EI.size()) v.emplace_back("frame.EI" + i, &f.EI[k]);
    if (k < f.floor_mass.size()) v.emplace_back("frame.floor_mass" + i, &f.floor_mass[k]);
  }
  return v;
}

std::vector<ParameterRow> parameters(const Scenario& sc) {
  std::vector<ParameterRow> r = {
      {{"rho_A", "a column's mass per unit length", "mass/length"}, [](Scenario& s) -> double& { return s.frame.rho_A; }},
      {{"zeta", "square-root (Chen–Russell) damping ratio ζ of the columns, d = 2ζ√(ρA·EI) (docs/theory.md §2.6)", "dimensionless"},
       [](Scenario& s) -> double& { return s.frame.zeta; }},
      {{"tau", "Kelvin–Voigt time constant of the columns, c = τ·EI: mode j's damping ratio τω_j/2 (docs/theory.md §2.6)", "time"},
       [](Scenario& s) -> double& { return s.frame.tau; }}};
  for (std::size_t k = 0; k < sc.frame.EI.size(); ++k) {
    const std::string n = std::to_string(k + 1);
    r.push_back({{"EI_" + n, "bending stiffness of a column of storey " + n, "force·length²"},
                 [k](Scenario& s) -> double& { return s.frame.EI[k]; }});
  }
  for (std::size_t k = 0; k < sc.frame.floor_mass.size(); ++k) {
    const std::string n = std::to_string(k + 1);
    r.push_back({{"floor_mass_" + n, "mass of floor " + n + " (the rigid block on storey " + n + ")", "mass"},
                 [k](Scenario& s) -> double& { return s.frame.floor_mass[k]; }});
  }
  return r;
}

// "EI": every storey's columns.
void set_stiffness(Scenario& sc, const std::map<std::string, double>& values) {
  if (const auto it = values.find("EI"); it != values.end()) sc.frame.EI.assign(sc.frame.heights.size(), it->second);
}

// The horizontal displacement of the first column at 2·count + 2 heights up to the top floor.
std::vector<ShapeSensor> shape_stations(const Scenario& sc, int count) {
  std::vector<ShapeSensor> out;
  const int m = 2 * count + 2;
  const double H = sc.frame.height();
  for (int k = 1; k <= m; ++k)
    out.push_back(shape_sensor("w" + std::to_string(k), Site::Frame, SensorKind::Displacement, k == m ? H : H * k / m, {0, 1, 0}, 1.0));
  return out;
}

// Inputs and sensors on the frame (a height); its storeys are its stiffness sections.
void check(const Scenario& sc) {
  for (std::size_t i = 0; i < sc.inputs.size(); ++i)
    if (sc.inputs[i].at != Site::Frame)
      fail_field(sc.source, "inputs[" + std::to_string(i) + "].at", "must be 'frame' for a frame structure", quoted(sc.inputs[i].at));
  for (std::size_t k = 0; k < sc.sensors.size(); ++k)
    if (sc.sensors[k].at != Site::Frame)
      fail_field(sc.source, "sensors[" + std::to_string(k) + "].at", "must be 'frame' for a frame structure", quoted(sc.sensors[k].at));
  if (sc.identification.sections > 1)
    fail_field(sc.source, "identification.sections", "must be 0 or 1 for a frame (its storeys are its sections)",
               std::to_string(sc.identification.sections));
}

}  // namespace

const KindTable& frame_kind() {
  static const KindTable t{[](const Scenario& sc) { return sc.frame.height(); },
                           numbers,
                           {},
                           [](Scenario&) { return std::vector<std::pair<std::string, bool*>>{}; },
                           parameters,
                           set_stiffness,
                           shape_stations,
                           check};
  return t;
}

}  // namespace scoleid::io
