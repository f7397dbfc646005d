#pragma once
// The identifier's view of one structure kind (docs/theory.md §2–§4): its finite-element model on
// the identifier's mesh, its named parameters and its model coefficients at a scenario's values.
// make_structure() is the one place that looks at scenario.structure: a structure kind is its FE
// model file (which defines its FEStructure and its make_<kind>_structure factory) and one line
// in the registry (structure.cpp).
#include <memory>
#include <string>
#include <vector>

#include "scoleid/identify/inverse/physical_parameterization.h"
#include "scoleid/identify/fe/structural_model.h"
#include "scoleid/io/scenario.h"

namespace scoleid::identify {

class FEStructure {
public:
  virtual ~FEStructure() = default;
  virtual const StructuralModel& model() const = 0;
  virtual int elements() const = 0;
  virtual double length() const = 0;
  // The structure's physical quantities at sc's values, their groups and coefficients
  // (inverse/physical_parameterization.h).
  virtual ParameterSpace parameter_space(const io::Scenario& sc) const = 0;
  // The named parameters of sc.identification, starting from sc's structure values: the
  // scenario's own, or (for the true values) the truth's. Names the door took
  // (identify::check_parameters); a refused one is a std::logic_error here.
  std::unique_ptr<PhysicalParameterization> parameterize(const io::Scenario& sc) const;
  // Model coefficients at sc's structure values.
  virtual VectorXd coefficients(const io::Scenario& sc) const = 0;
  // The kind's exact undamped natural frequencies [Hz], the `count` lowest, at sc's structure
  // values (a closed form or a dynamic-stiffness solution, independent of the mesh), and `what`
  // names the solution; empty where the kind has none for sc's configuration.
  virtual std::vector<double> exact_hz(const io::Scenario& sc, int count, std::string& what) const {
    (void)sc, (void)count;
    what.clear();
    return {};
  }
};

// The FE model of the scenario's structure on `elements` elements (its inputs and sensors
// attached). The scenario is a validated one (io::validate_scenario, identify::check_scenario):
// anything else is a std::logic_error.
std::unique_ptr<FEStructure> make_structure(const io::Scenario& sc, int elements);
// The kinds make_structure knows.
std::vector<std::string> structure_kinds();

}  // namespace scoleid::identify
