#pragma once
// The fields the scenario reader asks for, by their dotted paths: the schema as the code holds it,
// which docs/scenario.md documents field by field (and a unit test holds the two to each other).
//
// While a ScenarioFieldRecorder is alive, every field that parse_scenario and truth_scenario ask a
// scenario for on this thread, whether the scenario gives it or not, is noted with its path as
// messages write it, list indices written `[]`: `identification.band`, `inputs[].signal.amplitude`,
// `inputs[].signal[].type` (a signal written as a list of terms), `truth.overrides.sensors[].bias`.
// A field is noted when its parser asks for it, so the set depends on the scenario: a sine term's
// `frequency` is asked only of a sine, `inputs[].conditioning.offset.mean_before` only of an offset
// written as a map. Keys a map holds by name (identification.initial, identification.uncertain)
// are the map's own field, not fields of their own.
#include <set>
#include <string>

namespace scoleid::io {

class ScenarioFieldRecorder {
public:
  // Starts noting on this thread; a recorder made while another is alive notes in its place until
  // it goes.
  ScenarioFieldRecorder();
  ~ScenarioFieldRecorder();
  ScenarioFieldRecorder(const ScenarioFieldRecorder&) = delete;
  ScenarioFieldRecorder& operator=(const ScenarioFieldRecorder&) = delete;

  // The paths noted so far.
  const std::set<std::string>& fields() const { return fields_; }

private:
  std::set<std::string> fields_;
  std::set<std::string>* outer_;
};

}  // namespace scoleid::io
