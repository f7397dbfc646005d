#pragma once
// The mismatch suite (docs/theory.md §11.5): how identification on the Simbody truth degrades when
// the truth differs from the identifier's model, family by family, and whether the identifier's
// reported uncertainty interval (identify/include/scoleid/identify/inverse/interval.h) covers the
// truth.
//
// A suite file (crosscheck/mismatch/*.yaml) describes one family:
//   family:      name (the file's results are <family>.json)
//   mismatch:    what differs, in words;   size_unit: the unit of the sizes below
//   reason:      one line: why the bounds in `expect` are what they are (they come from measurement)
//   scenario:    the base scenario (built-in name, or a path relative to the suite file)
//   overlay:     YAML merged onto the base for every case (maps merge key by key, anything else
//                replaces), e.g. sensors, truth.segments
//   cases:       [ {label, size, overlay} ]   each case: the base + overlay + the case's overlay
//   noise:       {relative: r, seeds: K, seed: s0}  optional: Gaussian noise of r × each sensor's
//                RMS, K draws on one noise-free truth (added here; draw j of case k seeded s0 + 1000003 k + j)
//   expect:      {max_relative_error: {param: bound}, flagged: [param], all_covered: bool,
//                 rate: [lo, hi] | {param: [lo, hi]} (observed order against size: with three or
//                 more cases in geometric progression the self-convergence order of the estimates,
//                 richardson.h, and the Richardson limit's error is reported; with two, the
//                 order of the error),
//                 scatter_over_crb: [lo, hi], noise_bias_sigmas: b}
// Every case runs the truth (model/, written as truth.csv/truth.json as scole-truth writes them)
// and the identifier on it (identify/, from the files), with the interval.
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "scoleid/io/scenario.h"

namespace scoleid::crosscheck {

struct SuiteCase {
  std::string label;
  double size = 0.0;
  std::string overlay;  // YAML text of the case's own overlay
};

struct SuiteExpect {
  std::map<std::string, double> max_relative_error;
  std::vector<std::string> flagged;
  bool all_covered = false;
  std::map<std::string, std::pair<double, double>> rate;  // by parameter; "" = every parameter
  std::optional<std::pair<double, double>> scatter_over_crb;
  double noise_bias_sigmas = 2.0;
};

struct SuiteFile {
  std::string path, family, mismatch, size_unit, reason, base, overlay;
  std::vector<SuiteCase> cases;
  double noise_relative = 0.0;
  int seeds = 0;
  unsigned noise_seed = 1;  // seed of the first noise draw; case k, draw s use noise_seed + 1000003 k + s
  SuiteExpect expect;
};

// Reads and checks a suite file: one io::InputError line naming the file, the field and the value.
SuiteFile load_suite_file(const std::string& path);
// The suite files of a directory, sorted by name.
std::vector<std::string> suite_files(const std::string& dir);
// The scenario of case `k`: base + file overlay + case overlay, parsed and validated.
io::Scenario case_scenario(const SuiteFile& f, std::size_t k);

struct SuiteOptions {
  int seeds = 0;          // > 0: overrides the file's noise seeds
  bool progress = true;
};

// Runs every case of the family (truths under `out`/truths/<family>/<label>/) and returns the
// results as JSON (the schema of <family>.json), including each expectation and whether it held.
nlohmann::json run_suite_file(const SuiteFile& f, const std::string& out, const SuiteOptions& opt);

// The suite over the families' results: coverage and sharpness, report.md, suite.csv, suite.gp.
struct SuiteSummary {
  int cases = 0;          // parameter estimates counted (not flagged; one per case, the first seed of noise cases)
  int covered = 0;
  double coverage = 0.0;
  double median_relative_half_width = 0.0;
  double median_relative_error = 0.0;
  double sharpness = 0.0;  // median half-width / median error
  bool expectations_met = true;
  std::vector<std::string> failures;  // "family: what did not hold"
};
SuiteSummary summarise_suite(const std::vector<nlohmann::json>& families);
// A family's results file (results/<family>.json) as run_family writes it, or io::InputError naming
// `file` and the field (json_shape.h): checked before summarise_suite and suite_report read it.
void check_suite_result(const nlohmann::json& family_result, const std::string& file);
// report.md, suite.csv (one row per case and parameter), suite.gp (error and interval against the
// mismatch size, one panel per family) and suite.json: file name → contents.
std::map<std::string, std::string> suite_report(const std::vector<nlohmann::json>& families, const SuiteSummary& s);

}  // namespace scoleid::crosscheck
