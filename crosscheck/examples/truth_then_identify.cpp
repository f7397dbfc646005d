// Example: a Simbody truth, then the finite-element identifier on its data file — the two front
// doors (scoleid/truth.h, scoleid/identify.h) and the file between them.
//
// Sample run (build/crosscheck/examples/truth-then-identify-example /tmp/truth-example):
//
//   step 1: scenario paper-beam-1 (Paper Case I: simply supported beam, step load and sensor at
//           midspan), truth on 40 segments
//   step 2: wrote /tmp/truth-example/truth/truth.csv (1001 samples: P w_mid) and truth.json
//   step 3: identified q1 q2 from it: converged (step_tolerance), 4 iterations
//   step 4: parameter  estimate     truth        rel.error  ± interval covered
//           q1         3.4327e+02   3.4328e+02   -3.7e-05   1.98e-01    yes
//           q2         1.4942e-02   1.4925e-02   1.1e-03    2.69e-05    yes
//
// The steps are those of any study across the gap between two models: describe the structure and
// the experiment once (a scenario), simulate it with the independent multibody truth, hand its file
// to the identifier, and read the estimates against the values the truth was built with. The truth
// is a chain of rigid segments (docs/theory.md §9), the identifier a Hermite finite-element model
// (§2): neither sees the other's discretisation, so the error left is the gap between them, which
// the identifier's interval (§8) is meant to cover.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "scoleid/identify.h"
#include "scoleid/truth.h"

using namespace scoleid;

int main(int argc, char** argv) {
  const std::filesystem::path dir = argc > 1 ? argv[1] : "truth-example";
  std::filesystem::create_directories(dir);

  // Step 1. The scenario: the paper's Case I, identified from a start about 12 % off.
  const io::Scenario sc = io::load_scenario("paper-beam-1");
  std::printf("step 1: scenario %s (%s), truth on %d segments\n", sc.name.c_str(), sc.description.c_str(), sc.truth.segments);

  // Step 2. The truth: Simbody integrates the chain and samples the sensors; truth.csv holds t, the
  // inputs and the sensors, truth.json what each column is and the true parameters.
  const Truth truth = simulate_truth(sc);
  const std::string truth_dir = (dir / "truth").string();
  write_truth(truth, truth_dir);
  std::printf("step 2: wrote %s/truth.csv (%zu samples:", truth_dir.c_str(), truth.table.t.size());
  for (const auto& n : truth.table.names) std::printf(" %s", n.c_str());
  std::printf(") and truth.json\n");

  // Step 3. The identification from the file, as scole-identify --data would run it.
  const Identification id = identify_parameters(sc, DataSource::file(truth_dir + "/truth.csv"), IdentifyOptions{});
  const auto& r = id.result();
  std::printf("step 3: identified");
  for (const auto& n : id.names()) std::printf(" %s", n.c_str());
  std::printf(" from it: %s (%s), %d iterations\n", id.converged() ? "converged" : "NOT converged",
              identify::to_string(r.summary.termination), r.summary.iterations_done);
  id.write((dir / "identify").string());

  // Step 4. The estimates against the truth's values (truth.json gives them), with the interval.
  bool ok = id.converged();
  std::printf("step 4: %-10s %-12s %-12s %-10s %-11s %s\n", "parameter", "estimate", "truth", "rel.error", "± interval",
              "covered");
  for (std::size_t i = 0; i < id.names().size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const double q = id.estimate()[e], t = r.truth.at(id.names()[i]);
    const double hw = r.interval.half_width.size() > e ? r.interval.half_width[e] : std::nan("");
    const bool covered = std::abs(q - t) <= hw;
    std::printf("        %-10s %-12.4e %-12.4e %-10.1e %-11.2e %s\n", id.names()[i].c_str(), q, t, q / t - 1.0, hw,
                covered ? "yes" : "NO");
    ok = ok && r.ident.identifiable[i] && covered;
  }
  return ok ? 0 : 1;
}
