// docs/scenario.md against the scenario reader: every field the reader asks a scenario for is
// documented, and every documented field is one the reader asks for.
//
// The reader's fields are recorded (scenario_schema.h) while it parses every built-in, every
// scenario file of the repository and the scenarios below, which between them take every branch
// of the schema (each signal type, each form of conditioning, supports, attachments, both
// structures, truth overrides). The documented fields are the first cells of the rows of the
// document's field tables: the tables whose header's first cell is `field`; each such cell holds
// one or more paths in backticks (`beam.supports.left.k_w`, `beam.supports.right.k_w`).
// docs/scenario.md writes two families once: a signal term's fields as `inputs[].signal.FIELD`,
// whether the signal is one term or a list of them (`inputs[].signal[].FIELD`), and the fields of
// truth.overrides.beam, .scole and .frame as those of beam, scole and frame.
#include "common/test_data.h"
#include "scoleid/io/builtin.h"
#include "scoleid/io/error.h"
#include "scoleid/io/scenario.h"
#include "scoleid/io/scenario_schema.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

using namespace scoleid::io;
namespace fs = std::filesystem;

namespace {

fs::path source_root() { return fs::path(SCOLEID_TEST_DATA_DIR).parent_path().parent_path(); }

// A beam scenario with every beam field, every signal type, every form of conditioning, both
// kinds of sensor that carry a field of their own, and the truth's overrides of each.
const char* const kEveryBeamField = R"(
name: every-beam-field
description: "Every field of a beam scenario"
structure: beam
units: SI
beam:
  length: 2
  left: pinned
  right: free
  rho_A: 1.5
  EI: [100, 120]
  zeta: 0.01
  c_kv: 0.001
  tip_mass: 0.01
  tip_inertia: 1.0e-5
  supports:
    left: {k_w: 0, k_theta: 500, c_w: 0, c_theta: 0.1}
    right: {k_w: 1000, k_theta: 10, c_w: 0.1, c_theta: 0.01}
  attachments:
    - {name: fixture, location: 1.2, mass: 0.05, inertia: 1.0e-6, k_w: 10, k_theta: 1, c_w: 0.01, c_theta: 0.001}
inputs:
  - name: F
    at: beam
    kind: force
    location: 1.5
    direction: [0, 1, 0]
    unit: N
    signal_from: auto
    interpolation: cubic
    column: "Force [N]"
    column_unit: N
    conditioning: {offset: {mean_before: 0.01}, scale: 1.02, sign: -1, detrend: true, window: [0, 0.5]}
    signal:
      - {type: step, amplitude: 1, t0: 0}
      - {type: pulse, amplitude: 1, t0: 0.1, width: 0.05}
      - {type: bangbang, amplitude: 1, t0: 0.2, width: 0.1}
      - {type: haversine, amplitude: 1, t0: 0.3, width: 0.05}
      - {type: sine, amplitude: 1, t0: 0, frequency: 5, phase: 0.1, duration: 0.5}
      - {type: chirp, amplitude: 1, t0: 0, f0: 1, f1: 20, duration: 0.8}
      - {type: table, times: [0, 0.1, 0.2], values: [0, 1, 0]}
  - {name: M, kind: moment, location: 0.5, signal: {type: sine, amplitude: 0.1, frequency: 3}, signal_from: scenario,
     interpolation: linear, conditioning: {offset: mean, window: none}}
  - {name: F2, location: 1, signal: {type: table, times: [0, 1], values: [0, 1]}, signal_from: data,
     conditioning: {offset: 0.2, window: auto}}
sensors:
  - {name: w_tip, at: beam, kind: displacement, location: 2, direction: y, unit: m, noise_std: 1.0e-6, column: "w tip [mm]",
     column_unit: mm, conditioning: {offset: none, scale: 1, sign: 1, detrend: false}}
  - {name: eps, kind: strain, location: 0.2, offset: 0.0015, conditioning: {offset: {mean_before: 0.01}}}
  - {name: rel, kind: relative_displacement, location: 1.0, reference: 0.5}
simulation: {duration: 1, sample_interval: 0.001, seed: 3}
data: {time_column: "Time [s]", time_unit: ms, sample_rate: 1000}
identification:
  parameterization: physical
  estimate: [EI_1, EI_2, rho_A]
  initial: {EI_1: 90, EI_2: 110}
  elements: 8
  sections: 2
  data_elements: 16
  method: gauss-newton
  max_iterations: 20
  gradient_tolerance: 1.0e-8
  step_tolerance: 1.0e-4
  continuation_misfit: 0.1
  band: [1, 100]
  steepest_weights: [1, 1, 1]
  integrator: bdf
  time_step: 1.0e-4
  step_rule: data
  rtol: 1.0e-7
  model_error: 0.02
  restarts: 1
  start: plain
  model: linear
  smoothness: discrepancy
  uncertain: {beam.tip_mass: 0.001}
truth:
  segments: 20
  integrator: auto
  accuracy: 1.0e-8
  output_interval: 0.002
  anti_alias_hz: 100
  large_motion: false
  overrides:
    beam: {EI: [105, 125], supports: {left: {k_theta: 520}, right: {k_w: 900}}, attachments: [{name: fixture, mass: 0.055}]}
    sensors:
      - {name: w_tip, location: 1.98, bias: 1.0e-6, drift: 1.0e-7}
      - {name: eps, offset: 0.0016}
      - {name: rel, reference: 0.55}
)";

// A SCOLE scenario with every SCOLE field and the truth's overrides of a structure field and of a
// sensor's station and direction.
const char* const kEveryScoleField = R"(
name: every-scole-field
structure: scole
units: slug-ft-s
scole:
  length: 130
  rho_A: 0.0956
  EI: 4.0e7
  EI_roll: 4.0e7
  EI_pitch: 4.1e7
  GJ: 4.0e7
  rho_I_psi: 0.9089
  zeta: 0.003
  bending_rotary_inertia: true
  shuttle: {mass: 6366, Ixx: 905443, Iyy: 6789100, Izz: 7086601, Ixy: 0, Ixz: 0, Iyz: 0}
  reflector: {mass: 12.42, Ixx: 4969, Iyy: 4969, Izz: 9938, Ixy: 0, Ixz: 0, Iyz: 0}
  reflector_rx: 18.75
  reflector_ry: -32.5
  mast_root: [0, 0, 0]
  actuator_locations: [43.3, 86.7]
  actuator_mass: 0.2
  actuator_stroke: 5
  actuator_stiffness: 0
  actuator_damping: 0
  actuator_lag: 0
inputs:
  - {name: F_a1, at: actuator1, kind: force, direction: y, unit: lbf, signal: {type: haversine, amplitude: 0.01, width: 0.4}}
sensors:
  - {name: los, at: reflector, kind: line_of_sight, direction: x, unit: rad}
  - {name: roll_tip, at: mast, location: 130, direction: y, unit: ft}
simulation: {duration: 2, sample_interval: 0.01}
identification: {parameterization: paper, estimate: [q1, q2], model: nonlinear}
truth:
  large_motion: true
  overrides:
    scole: {reflector_rx: 19, actuator_lag: 0.02}
    sensors: [{name: roll_tip, location: 128, direction: [0.0175, 0.9998, 0]}]
)";

// The path as docs/scenario.md writes it (see the top of this file).
std::string documented_form(std::string path) {
  const std::string term = ".signal[].";
  if (const auto at = path.find(term); at != std::string::npos) path.replace(at, term.size(), ".signal.");
  const std::string overrides = "truth.overrides.";
  for (const char* section : {"beam.", "scole.", "frame."})
    if (path.rfind(overrides + section, 0) == 0) path.erase(0, overrides.size());
  return path;
}

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// The paths in the first cells of the rows of the document's field tables.
std::set<std::string> documented_fields(const std::string& markdown, std::vector<std::string>& bad_rows) {
  std::set<std::string> out;
  std::istringstream in(markdown);
  std::string line;
  bool in_table = false, field_table = false;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] != '|') {
      in_table = false;
      continue;
    }
    const auto end = line.find('|', 1);
    const std::string cell = trimmed(line.substr(1, end == std::string::npos ? std::string::npos : end - 1));
    if (!in_table) {  // the header
      in_table = true;
      field_table = cell == "field";
      continue;
    }
    if (!field_table || cell.find_first_not_of("-: ") == std::string::npos) continue;
    std::size_t n = 0;
    for (std::size_t at = cell.find('`'); at != std::string::npos;) {
      const auto close = cell.find('`', at + 1);
      if (close == std::string::npos) break;
      out.insert(cell.substr(at + 1, close - at - 1));
      ++n;
      at = cell.find('`', close + 1);
    }
    if (n == 0) bad_rows.push_back(line);
  }
  return out;
}

struct Corpus {
  std::set<std::string> asked;          // in the documented form
  std::vector<std::string> parsed;      // the scenarios that parse
};

// Adds the fields parsing `text` asks for, if it is a scenario; returns its error ("" if it parses).
std::string add(Corpus& c, const std::string& text, const std::string& source) {
  ScenarioFieldRecorder recorder;
  try {
    parse_scenario(text, source);
  } catch (const InputError& e) {
    return e.what();
  }
  for (const auto& f : recorder.fields()) c.asked.insert(documented_form(f));
  c.parsed.push_back(source);
  return "";
}

// The built-ins, every YAML or JSON file under the repository's sources that parses as a scenario,
// and the scenarios above.
const Corpus& corpus() {
  static const Corpus c = [] {
    Corpus c;
    for (const auto& b : builtin_scenario_texts()) EXPECT_EQ(add(c, b.yaml, "built-in " + b.name), "") << b.name;
    for (const char* dir : {"io", "identify", "model", "crosscheck", "tests"}) {
      const fs::path top = source_root() / dir;
      if (!fs::is_directory(top)) continue;
      for (auto it = fs::recursive_directory_iterator(top); it != fs::recursive_directory_iterator(); ++it) {
        const std::string name = it->path().filename().string();
        if (it->is_directory() && (name.rfind("build", 0) == 0 || name.rfind(".", 0) == 0)) {
          it.disable_recursion_pending();
          continue;
        }
        const std::string ext = it->path().extension().string();
        if (it->is_regular_file() && (ext == ".yaml" || ext == ".yml" || ext == ".json"))
          add(c, scoleid::test::slurp(it->path()), it->path().string());
      }
    }
    EXPECT_EQ(add(c, kEveryBeamField, "every-beam-field"), "");
    EXPECT_EQ(add(c, kEveryScoleField, "every-scole-field"), "");
    return c;
  }();
  return c;
}

std::set<std::string> documented() {
  std::vector<std::string> bad_rows;
  const std::string text = scoleid::test::slurp(source_root() / "docs" / "scenario.md");
  EXPECT_FALSE(text.empty()) << "docs/scenario.md cannot be read";
  auto fields = documented_fields(text, bad_rows);
  for (const auto& row : bad_rows) ADD_FAILURE() << "docs/scenario.md: a field table's row names no field in backticks: " << row;
  return fields;
}

std::string listed(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += "\n  " + x;
  return s;
}

}  // namespace

TEST(ScenarioDoc, TheCorpusCoversBothStructuresAndTheRepositoryFiles) {
  const Corpus& c = corpus();
  // The built-ins, the two scenarios above and the repository's scenario files.
  EXPECT_GT(c.parsed.size(), builtin_scenario_texts().size() + 20) << listed(c.parsed);
  EXPECT_TRUE(c.asked.count("inputs[].signal.frequency"));
  EXPECT_TRUE(c.asked.count("scole.actuator_lag"));
  EXPECT_TRUE(c.asked.count("truth.overrides.sensors[].bias"));
}

TEST(ScenarioDoc, EveryFieldTheReaderAsksForIsDocumented) {
  const auto doc = documented();
  std::vector<std::string> missing;
  for (const auto& f : corpus().asked)
    if (!doc.count(f)) missing.push_back(f);
  EXPECT_TRUE(missing.empty()) << missing.size()
                               << " field(s) the scenario reader asks for have no row \"| `path` |\" in a field table of "
                                  "docs/scenario.md:"
                               << listed(missing);
}

TEST(ScenarioDoc, EveryDocumentedFieldIsOneTheReaderAsksFor) {
  const auto doc = documented();
  EXPECT_GT(doc.size(), 100u);
  std::vector<std::string> stale;
  for (const auto& f : doc)
    if (!corpus().asked.count(f)) stale.push_back(f);
  EXPECT_TRUE(stale.empty()) << stale.size()
                             << " field(s) documented in docs/scenario.md that the scenario reader never asks for:"
                             << listed(stale);
}

// An unknown key is refused with the fields known where it stands: those documented there.
TEST(ScenarioDoc, AnUnknownFieldIsRefusedWithTheDocumentedFieldsOfItsSection) {
  const auto doc = documented();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "nmae: x\n"},
      {"beam", "beam: {lenght: 3}\n"},
      {"scole", "structure: scole\nscole: {lenght: 3}\n"},
      {"inputs[]", "inputs: [{nmae: a}]\n"},
      {"sensors[]", "sensors: [{nmae: a}]\n"},
      {"simulation", "simulation: {durration: 1}\n"},
      {"data", "data: {time_colum: t, sample_rate: 100}\n"},
      {"identification", "identification: {metod: lbfgs}\n"},
      {"truth", "truth: {segmnts: 3}\n"}};
  for (const auto& [section, yaml] : cases) {
    const std::string e = scoleid::test::scenario_error(yaml, "x.yaml");
    ASSERT_NE(e.find("is not a known field"), std::string::npos) << yaml << e;
    const auto from = e.find("known here: ");
    ASSERT_NE(from, std::string::npos) << e;
    const auto to = e.find(')', from);
    std::set<std::string> known;
    std::istringstream list(e.substr(from + 12, to - from - 12));
    for (std::string k; std::getline(list, k, ',');) known.insert((section.empty() ? "" : section + ".") + trimmed(k));
    std::set<std::string> children;
    for (const auto& f : doc) {
      if (!section.empty() && f.rfind(section + ".", 0) != 0) continue;
      const std::string rest = section.empty() ? f : f.substr(section.size() + 1);
      if (rest.find_first_of(".[") == std::string::npos) children.insert(f);
    }
    EXPECT_EQ(known, children) << "section '" << section << "': " << e;
  }
}
