#include "scoleid/io/scenario_fields.h"

#include <utility>

#include "structure_kinds.h"

namespace scoleid::io {

namespace {

// The structure kind's numbers (structure_kinds.h), then every station sensor's location.
std::vector<std::pair<std::string, double*>> numbers(Scenario& sc) {
  auto v = kind_table(sc.structure).numbers(sc);
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
  for (const KindTable* kind : kind_tables())
    for (const auto& p : kind->signed_paths)
      if (p == path) return true;
  return false;
}

bool* bool_field(Scenario& sc, const std::string& path) {
  for (auto& [name, ptr] : kind_table(sc.structure).switches(sc))
    if (name == path) return ptr;
  return nullptr;
}

std::string truth_field(const Scenario& scenario, const Scenario& truth, const std::string& path) {
  Scenario a = scenario, b = truth;
  const auto find = [&path](Scenario& sc) -> const double* {
    if (const double* v = numeric_field(sc, path)) return v;
    if (const auto extra = kind_table(sc.structure).truth_numbers)
      for (auto& [name, ptr] : extra(sc))
        if (name == path) return ptr;
    return nullptr;
  };
  const double* x = find(a);
  const double* y = find(b);
  return x && y && *x != *y ? "truth.overrides." + path : path;
}

std::vector<std::string> field_paths(const Scenario& sc) {
  Scenario copy = sc;
  std::vector<std::string> v;
  for (auto& [name, ptr] : numbers(copy)) v.push_back(name);
  for (auto& [name, ptr] : kind_table(sc.structure).switches(copy)) v.push_back(name);
  return v;
}

}  // namespace scoleid::io
