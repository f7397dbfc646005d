// Example: identify a beam's EI and ρA from a measurement file, through the public API
// (scoleid/identify.h: scoleid::prepare, scoleid::identify_parameters).
//
// Sample run (build/identify/examples/identify-beam-example /tmp/beam-example):
//
//   step 1: scenario paper-beam-1, estimating q1 q2
//   step 2: wrote /tmp/beam-example/measured.csv (1001 samples, sensor w_mid, 2e-05 m noise)
//   step 3: problem: 10 elements, 2 parameters, data /tmp/beam-example/measured.csv
//   step 4: converged (step_tolerance) after 4 iterations
//   step 5:  q1  estimate 3.4327e+02  truth 3.4328e+02  error -5.3e-05  std 6.3e-03
//            q2  estimate 1.4925e-02  truth 1.4925e-02  error -1.6e-05  std 9.1e-07
//
// The five steps are what any study does: describe the structure and the experiment (a scenario),
// get measurements into a CSV file (here synthesised from a finer model, in practice from a test),
// build the identification problem from the two, run the optimiser, and read the estimates with
// their uncertainty. Theory: docs/theory.md §2 (beam), §6 (costate gradient), §7 (Gauss–Newton),
// §8 (standard deviations).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "scoleid/identify.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/scenario.h"

using namespace scoleid;

int main(int argc, char** argv) {
  const std::filesystem::path dir = argc > 1 ? argv[1] : "beam-example";
  std::filesystem::create_directories(dir);

  // Step 1. The scenario: a simply supported beam (the paper's Case I), a step load at midspan, a
  // displacement sensor there; q1 = EI/ρA and q2 = 1/ρA to be found from about 12 % off. We add sensor
  // noise of 20 µm (0.2 % of the static deflection) so that the standard deviations mean something.
  io::Scenario sc = io::load_scenario("paper-beam-1");
  sc.sensors[0].noise_std = 2e-5;
  std::printf("step 1: scenario %s, estimating", sc.name.c_str());
  for (const auto& n : sc.identification.estimate) std::printf(" %s", n.c_str());

  // Step 2. The measurement file: t, the input and the sensor, one row per sample. Here it is
  // synthesised on a mesh four times finer than the identifier's, with noise; a test lab's file
  // of the same layout is read the same way.
  const identify::Measurements m =
      identify::synthesize(sc, 4 * sc.identification.elements, 1e-8, 1e-3, /*add_noise=*/true);
  const io::DataTable table = identify::measurement_table(sc, m);
  const std::string csv = (dir / "measured.csv").string();
  io::write_csv(csv, table);
  std::printf("\nstep 2: wrote %s (%zu samples, sensor %s, %g m noise)\n", csv.c_str(), m.t.size(),
              sc.sensors[0].name.c_str(), sc.sensors[0].noise_std);

  // Step 3. The identification problem: the FE model on the identifier's mesh, the named
  // parameters, the input signals and the measurements matched to the sensors by column name.
  const auto problem = scoleid::prepare(sc, scoleid::DataSource::file(csv));
  std::printf("step 3: problem: %d elements, %d parameters, data %s\n", problem->structure->elements(),
              problem->params->size(), problem->data_source.c_str());

  // Step 4. Run: Gauss–Newton on the costate/sensitivity gradient, then the Fisher information at
  // the estimate for the standard deviations and the identifiability flags.
  const scoleid::Identification id = scoleid::identify_parameters(problem, scoleid::IdentifyOptions{});
  const identify::RunResult& r = id.result();
  std::printf("step 4: %s (%s) after %zu iterations\n", id.converged() ? "converged" : "NOT converged",
              identify::to_string(r.summary.termination), r.summary.iterations.size() - 1);

  // Step 5. The answer, against the values the synthetic data were made with.
  const auto truth = identify::make_problem(sc, std::nullopt)->true_values;
  bool ok = id.converged();
  std::printf("step 5:");
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const double t = truth.at(r.names[i]), err = r.estimate[e] / t - 1.0;
    std::printf("%s  %-3s estimate %.4e  truth %.4e  error %8.1e  std %.1e\n", i ? "       " : "", r.names[i].c_str(),
                r.estimate[e], t, err, r.ident.std[e]);
    ok = ok && r.ident.identifiable[i] && std::abs(err) < 1e-3;
  }
  return ok ? 0 : 1;
}
