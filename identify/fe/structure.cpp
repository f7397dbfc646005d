#include "scoleid/identify/fe/structure.h"

#include <cmath>
#include <functional>
#include <map>

#include "scoleid/identify/fe/beam_model.h"
#include "scoleid/identify/fe/frame_model.h"
#include "scoleid/identify/fe/scole_model.h"
#include "scoleid/io/error.h"

namespace scoleid::identify {

namespace {

class BeamStructure final : public FEStructure {
public:
  BeamStructure(const io::Scenario& sc, int elements)
      : fe_(build_beam(sc.beam, elements, sc.identification.sections, sc.inputs, sc.sensors, sc.source)) {}
  const StructuralModel& model() const override { return fe_.model; }
  int elements() const override { return fe_.elements; }
  double length() const override { return fe_.length; }
  std::unique_ptr<Parameterization> parameterize(const io::Scenario& sc) const override {
    return std::make_unique<PhysicalParameterization>(beam_parameter_space(fe_, sc.beam), sc.identification, sc.source);
  }
  VectorXd coefficients(const io::Scenario& sc) const override {
    VectorXd c = beam_coefficients(fe_, sc.beam.rho_A, sc.beam.EI, sc.beam.zeta, sc.beam.c_kv);
    for (std::size_t k = 0; k < fe_.points.size(); ++k)  // the point elements' values in sc (its truth's may differ)
      if (const double v = point_value(fe_.points[k], sc.beam); !std::isnan(v)) c[fe_.coef_point(static_cast<int>(k))] = v;
    return c;
  }

private:
  BeamFE fe_;
};

class ScoleStructure final : public FEStructure {
public:
  ScoleStructure(const io::Scenario& sc, int elements)
      : fe_((check(sc), build_scole(sc.scole, elements, sc.inputs, sc.sensors, sc.source))) {}
  const StructuralModel& model() const override { return fe_.model; }
  int elements() const override { return fe_.elements; }
  double length() const override { return fe_.spec.length; }
  std::unique_ptr<Parameterization> parameterize(const io::Scenario& sc) const override {
    return std::make_unique<PhysicalParameterization>(scole_parameter_space(sc.scole), sc.identification, sc.source);
  }
  VectorXd coefficients(const io::Scenario& sc) const override { return scole_coefficients(sc.scole); }

private:
  static int check(const io::Scenario& sc) {
    if (sc.identification.sections > 1)
      io::fail_field(sc.source, "identification.sections", "must be 0 or 1 for a scole structure (uniform mast)",
                     std::to_string(sc.identification.sections));
    return 0;
  }
  ScoleFE fe_;
};

class FrameStructure final : public FEStructure {
public:
  FrameStructure(const io::Scenario& sc, int elements)
      : fe_((check(sc), build_frame(sc.frame, elements, sc.inputs, sc.sensors, sc.source))) {}
  const StructuralModel& model() const override { return fe_.model; }
  int elements() const override { return fe_.elements; }
  double length() const override { return fe_.height; }
  std::unique_ptr<Parameterization> parameterize(const io::Scenario& sc) const override {
    return std::make_unique<PhysicalParameterization>(frame_parameter_space(fe_, sc.frame), sc.identification, sc.source);
  }
  VectorXd coefficients(const io::Scenario& sc) const override { return frame_coefficients(fe_, sc.frame); }

private:
  static int check(const io::Scenario& sc) {
    if (sc.identification.sections > 1)
      io::fail_field(sc.source, "identification.sections", "must be 0 or 1 for a frame (its storeys are its sections)",
                     std::to_string(sc.identification.sections));
    return 0;
  }
  FrameFE fe_;
};

using Factory = std::function<std::unique_ptr<FEStructure>(const io::Scenario&, int)>;

template <class S>
Factory factory() {
  return [](const io::Scenario& sc, int elements) { return std::make_unique<S>(sc, elements); };
}

// The registry: scenario.structure -> its FE model.
const std::map<std::string, Factory>& registry() {
  static const std::map<std::string, Factory> r = {{"beam", factory<BeamStructure>()},
                                                   {"scole", factory<ScoleStructure>()},
                                                   {"frame", factory<FrameStructure>()}};
  return r;
}

}  // namespace

std::unique_ptr<FEStructure> make_structure(const io::Scenario& sc, int elements) {
  const auto it = registry().find(io::to_string(sc.structure));
  if (it == registry().end()) {
    std::string list;
    for (const auto& k : structure_kinds()) list += (list.empty() ? "" : "|") + k;
    io::fail_field(sc.source, "structure", "is not supported by this identifier (" + list + ")", "'" + std::string(io::to_string(sc.structure)) + "'");
  }
  return it->second(sc, elements);
}

std::vector<std::string> structure_kinds() {
  std::vector<std::string> k;
  for (const auto& [name, f] : registry()) k.push_back(name);
  return k;
}

}  // namespace scoleid::identify
