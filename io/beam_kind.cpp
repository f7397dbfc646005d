// The beam's table (structure_kinds.h): a planar Euler–Bernoulli beam (docs/theory.md §2).
#include "structure_kinds.h"

#include "scoleid/io/error.h"
#include "scoleid/io/number.h"

namespace scoleid::io {

namespace {

ParameterInfo point_element_info(const std::string& group, const PointElement& e, const std::string& field) {
  const std::string where = group == "supports" ? "the " + e.name + " support" : "attachment '" + e.name + "'";
  if (field == "mass") return {point_element_parameter(group, e, "mass"), "mass of " + where, "mass"};
  if (field == "inertia") return {point_element_parameter(group, e, "inertia"), "rotary inertia of " + where, "mass·length²"};
  if (field == "k_w") return {point_element_parameter(group, e, "k_w"), "translational spring to ground of " + where, "force/length"};
  if (field == "k_theta") return {point_element_parameter(group, e, "k_theta"), "rotational spring to ground of " + where, "force·length/rad"};
  if (field == "c_w") return {point_element_parameter(group, e, "c_w"), "translational dashpot to ground of " + where, "force·time/length"};
  if (field == "lumped_mass") return {point_element_parameter(group, e, "lumped_mass"), "lumped mass (its own degree of freedom) of " + where, "mass"};
  if (field == "lumped_k") return {point_element_parameter(group, e, "lumped_k"), "spring joining the lumped mass to the beam at " + where, "force/length"};
  if (field == "lumped_c") return {point_element_parameter(group, e, "lumped_c"), "dashpot joining the lumped mass to the beam at " + where, "force·time/length"};
  if (field == "lumped_k_ground") return {point_element_parameter(group, e, "lumped_k_ground"), "spring from the lumped mass of " + where + " to ground", "force/length"};
  return {point_element_parameter(group, e, "c_theta"), "rotational dashpot to ground of " + where, "force·length·time/rad"};
}

std::vector<std::pair<std::string, double*>> numbers(Scenario& sc) {
  auto& b = sc.beam;
  std::vector<std::pair<std::string, double*>> v = {{"beam.length", &b.length}, {"beam.rho_A", &b.rho_A}, {"beam.zeta", &b.zeta}, {"beam.c_kv", &b.c_kv},
          {"beam.tip_mass", &b.tip_mass}, {"beam.tip_inertia", &b.tip_inertia}};
  // Point elements: beam.supports.left.k_theta, beam.attachments.clamp.location, .mass, ...
  for (auto* group : {&b.supports, &b.attachments}) {
    const std::string prefix = group == &b.supports ? "beam.supports." : "beam.attachments.";
    for (auto& e : *group) {
      if (group == &b.attachments) v.emplace_back(prefix + e.name + ".location", &e.location);
      // A support's fields that act on what its end holds are no numbers of the model.
      const EndCondition end = e.name == "left" ? b.left : b.right;
      for (const auto& [key, member] : point_element_fields()) {
        const std::string k = key;
        const bool on_w = displacement_field(k);
        if (group == &b.supports && (attachment_only_field(k) || end == EndCondition::Clamped ||
                                     (on_w && end == EndCondition::Pinned)))
          continue;
        v.emplace_back(prefix + e.name + "." + key, &(e.*member));
      }
    }
  }
  return v;
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
  // Every quantity a point element holds (> 0) is a parameter: supports.left.k_theta,
  // attachments.clamp.mass (docs/theory.md §2.5).
  for (const bool supports : {true, false}) {
    const auto& group = supports ? sc.beam.supports : sc.beam.attachments;
    for (std::size_t i = 0; i < group.size(); ++i)
      for (const auto& [key, member] : point_element_fields()) {
        if (!(group[i].*member > 0.0)) continue;
        const auto m = member;
        r.push_back({point_element_info(supports ? "supports" : "attachments", group[i], key),
                     [supports, i, m](Scenario& s) -> double& { return (supports ? s.beam.supports : s.beam.attachments)[i].*m; }});
      }
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

// Inputs, sensors and attachments on the beam; a force on an attachment's own degree of freedom
// names one with a lumped mass; a beam clamped at both ends needs two elements to move at all.
void check(const Scenario& sc) {
  for (std::size_t i = 0; i < sc.inputs.size(); ++i) {
    const InputSpec& in = sc.inputs[i];
    const std::string f = "inputs[" + std::to_string(i) + "]";
    if (in.at != Site::Beam) fail_field(sc.source, f + ".at", "must be 'beam' for a beam structure", quoted(in.at));
    if (in.attachment.empty()) continue;
    const PointElement* e = nullptr;
    for (const auto& a : sc.beam.attachments)
      if (a.name == in.attachment) e = &a;
    if (!e || !(e->lumped_mass > 0.0))
      fail_field(sc.source, f + ".attachment", "must name an attachment of the beam with a lumped_mass (beam.attachments[].name)",
                 "'" + in.attachment + "'");
  }
  // An attachment's station (declared uncertain, or overridden) stays on the beam.
  for (const auto& a : sc.beam.attachments)
    if (!(a.location >= 0.0 && a.location <= sc.beam.length))
      fail_field(sc.source, "beam.attachments." + a.name + ".location", "must lie on the beam [0, " + format_value(sc.beam.length) + "]",
                 format_value(a.location));
  for (std::size_t k = 0; k < sc.sensors.size(); ++k)
    if (sc.sensors[k].at != Site::Beam)
      fail_field(sc.source, "sensors[" + std::to_string(k) + "].at", "must be 'beam' for a beam structure", quoted(sc.sensors[k].at));
  if (sc.beam.left == EndCondition::Clamped && sc.beam.right == EndCondition::Clamped && sc.identification.elements < 2)
    fail_field(sc.source, "identification.elements",
               "must be >= 2 for a beam clamped at both ends (one element leaves no free degree of freedom)",
               std::to_string(sc.identification.elements));
}

}  // namespace

const KindTable& beam_kind() {
  static const KindTable t{[](const Scenario& sc) { return sc.beam.length; },
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
