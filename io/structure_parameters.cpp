#include "scoleid/io/structure_parameters.h"

#include "structure_kinds.h"

namespace scoleid::io {

std::vector<ParameterInfo> structure_parameter_table(const Scenario& sc) {
  std::vector<ParameterInfo> t;
  for (const auto& r : kind_table(sc.structure).parameters(sc)) t.push_back(r.info);
  return t;
}

std::map<std::string, double> structure_parameters(const Scenario& sc) {
  Scenario copy = sc;
  std::map<std::string, double> p;
  for (const auto& r : kind_table(sc.structure).parameters(sc)) p[r.info.name] = r.ref(copy);
  return p;
}

void set_structure_parameters(Scenario& sc, const std::map<std::string, double>& values) {
  // "EI" for every section / both planes first, so that a sectional or per-plane value wins.
  kind_table(sc.structure).set_stiffness(sc, values);
  for (const auto& r : kind_table(sc.structure).parameters(sc)) {
    const auto it = values.find(r.info.name);
    if (it != values.end()) r.ref(sc) = it->second;
  }
}

}  // namespace scoleid::io
