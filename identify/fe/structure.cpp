#include "scoleid/identify/fe/structure.h"

#include <stdexcept>
#include <map>

#include "scoleid/identify/fe/beam_model.h"
#include "scoleid/identify/fe/frame_model.h"
#include "scoleid/identify/fe/scole_model.h"
#include "scoleid/io/error.h"

namespace scoleid::identify {

namespace {

using Factory = std::unique_ptr<FEStructure> (*)(const io::Scenario&, int);

// The registry: scenario.structure -> its FE model (each factory in its kind's model file).
const std::map<std::string, Factory>& registry() {
  static const std::map<std::string, Factory> r = {{"beam", &make_beam_structure},
                                                   {"scole", &make_scole_structure},
                                                   {"frame", &make_frame_structure}};
  return r;
}
}  // namespace

std::unique_ptr<FEStructure> make_structure(const io::Scenario& sc, int elements) {
  const auto it = registry().find(io::to_string(sc.structure));
  if (it == registry().end())  // every kind of io::Structure has its row
    throw std::logic_error("make_structure: no finite-element model of structure '" + std::string(io::to_string(sc.structure)) + "'");
  return it->second(sc, elements);
}

std::unique_ptr<PhysicalParameterization> FEStructure::parameterize(const io::Scenario& sc) const {
  auto p = std::make_unique<PhysicalParameterization>(parameter_space(sc), sc.identification);
  if (const auto& r = p->refusal())
    throw std::logic_error("FEStructure::parameterize: " + r->field + " " + r->what + " (identify::check_parameters refuses it)");
  return p;
}

std::vector<std::string> structure_kinds() {
  std::vector<std::string> k;
  for (const auto& [name, f] : registry()) k.push_back(name);
  return k;
}

}  // namespace scoleid::identify
