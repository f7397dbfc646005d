#pragma once
// The physical parameters of a scenario's structure, by name: one table per structure kind that
// the truth (truth.json's true_parameters), the identifier (true values read back from a
// truth.json) and the reports read. A new physical parameter is one row of its kind's table
// (io/structure_kinds.h).
#include <map>
#include <string>
#include <vector>

#include "scoleid/io/scenario.h"

namespace scoleid::io {

struct ParameterInfo {
  std::string name;       // as in truth.json and identification.estimate (physical form)
  std::string meaning;
  std::string dimension;  // in the scenario's consistent unit system
};

// The table of sc.structure (for a beam with N > 1 EI sections, EI_1..EI_N replace EI).
std::vector<ParameterInfo> structure_parameter_table(const Scenario& sc);
// The structure's values by name (truth.json true_parameters).
std::map<std::string, double> structure_parameters(const Scenario& sc);
// Sets the values named in `values` that the structure has (EI: every section, or both SCOLE
// bending planes); other names are left alone.
void set_structure_parameters(Scenario& sc, const std::map<std::string, double>& values);

}  // namespace scoleid::io
