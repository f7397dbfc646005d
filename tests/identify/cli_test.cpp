// The scole-identify executable's contract for bad input, tested end to end through a shell:
// every input error (unknown scenario, unreadable or malformed YAML, out-of-range or unknown
// fields, unusable data CSV, bad command line) exits with code 2, prints exactly one line on
// stderr that names the source (file or scenario), the field and the offending value, and
// leaves no output file (identify.json, fit.csv, *.tmp.*) in the --out directory.
// Plus the positive paths: --list-scenarios, --help, and a small identification run without
// and then with --data (the data being the first run's measured column).
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>
#include "common/cli_support.h"
#include "scoleid/io/error.h"
#include "scoleid/io/scenario.h"
#include "common/test_data.h"

#ifndef SCOLE_IDENTIFY_EXE
#error "SCOLE_IDENTIFY_EXE must be defined to the path of the scole-identify executable"
#endif

namespace fs = std::filesystem;

namespace {

using Result = scoleid::test::CommandResult;
using scoleid::test::shell_quote;
using scoleid::test::slurp;
using scoleid::test::write_file;

// Non-empty-terminated lines of a stream's text ("a\nb\n" -> {a, b}; "a\nb" -> {a, b}).
std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : text) {
    if (c == '\n') {
      out.push_back(cur);
      cur.clear();
    } else {
      cur.push_back(c);
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

// A per-test scratch directory, unique across processes and tests, removed at the end.
class TempDir {
public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::random_device rd;
    const std::string name = std::string("scoleid-cli-") + (info ? info->name() : "x") + "-" +
                             std::to_string(::getpid()) + "-" + std::to_string(rd());
    path_ = fs::temp_directory_path() / name;
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }
  fs::path operator/(const std::string& s) const { return path_ / s; }

private:
  fs::path path_;
};

// Runs scole-identify with `args` from inside `dir`.
Result run(const std::vector<std::string>& args, const TempDir& dir) {
  return scoleid::test::run_command(SCOLE_IDENTIFY_EXE, args, dir.path());
}

// The --out directory may exist, but must hold no identify.json, no fit.csv, no *.tmp.* file.
void expect_no_outputs(const fs::path& out) {
  if (!fs::exists(out)) return;
  EXPECT_FALSE(fs::exists(out / "identify.json")) << out / "identify.json" << " left behind";
  EXPECT_FALSE(fs::exists(out / "fit.csv")) << out / "fit.csv" << " left behind";
  for (const auto& e : fs::recursive_directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    EXPECT_EQ(name.find(".tmp."), std::string::npos) << "temporary file left behind: " << e.path();
  }
}

// The input-error contract: exit 2, exactly one stderr line holding every one of `needles`
// (source, field, value), no output files. io::InputError lines also start "scole-identify: ";
// command-line usage errors (prefixed = false) are only held to exit 2 and one line.
void expect_input_error(const Result& r, const fs::path& out, const std::vector<std::string>& needles,
                        bool prefixed = true) {
  EXPECT_EQ(r.code, 2) << "stderr:\n" << r.err << "stdout:\n" << r.out;
  const auto ls = lines_of(r.err);
  EXPECT_EQ(ls.size(), 1u) << "stderr must be exactly one line, got:\n" << r.err;
  const std::string line = ls.empty() ? std::string() : ls.front();
  if (prefixed) {
    EXPECT_EQ(line.rfind("scole-identify: ", 0), 0u) << "line: " << line;
  }
  for (const auto& n : needles)
    EXPECT_NE(line.find(n), std::string::npos) << "'" << n << "' missing from stderr line: " << line;
  expect_no_outputs(out);
}

// A short cantilever case: step tip load, tip sensor, q1 = EI/rho_A and q2 = 1/rho_A. Ten
// elements keep the discretisation error against the (twice as fine) synthetic data well under
// 1e-3 (four elements give ~4e-3 on q1) while the whole run stays well under a second.
const std::string kGood = scoleid::test::test_scenario("cli_test/cli-good");

// kGood with the first occurrence of `from` replaced by `to`.
std::string good_with(const std::string& from, const std::string& to) { return scoleid::test::replaced(kGood, from, to); }

// Writes `yaml` to DIR/s.yaml, runs it with --out DIR/out, checks the input-error contract.
void expect_yaml_error(const std::string& yaml, const std::vector<std::string>& needles_after_source) {
  TempDir dir;
  const fs::path file = dir / "s.yaml", out = dir / "out";
  write_file(file, yaml);
  fs::create_directories(out);
  const Result r = run({"--scenario", file.string(), "--out", out.string(), "-q"}, dir);
  std::vector<std::string> needles{"scenario '" + file.string() + "'"};
  needles.insert(needles.end(), needles_after_source.begin(), needles_after_source.end());
  expect_input_error(r, out, needles);
}

// Writes `csv` to DIR/<name>, runs paper-beam-1 on it, checks the input-error contract.
void expect_csv_error(const std::string& name, const std::string& csv, const std::vector<std::string>& needles) {
  TempDir dir;
  const fs::path file = dir / name, out = dir / "out";
  write_file(file, csv);
  fs::create_directories(out);
  const Result r = run({"--scenario", "paper-beam-1", "--data", file.string(), "--out", out.string(), "-q"}, dir);
  std::vector<std::string> all{"data file '" + file.string() + "'"};
  all.insert(all.end(), needles.begin(), needles.end());
  expect_input_error(r, out, all);
}

// The columns of a numeric CSV with a header line; `header` receives the column names.
std::vector<std::vector<double>> csv_columns(const std::string& text, std::vector<std::string>& header) {
  std::vector<std::vector<double>> cols;
  const auto ls = lines_of(text);
  header.clear();
  if (ls.empty()) return cols;
  {
    std::stringstream h(ls[0]);
    std::string f;
    while (std::getline(h, f, ',')) header.push_back(f);
  }
  cols.assign(header.size(), {});
  for (std::size_t i = 1; i < ls.size(); ++i) {
    if (ls[i].empty()) continue;
    std::stringstream row(ls[i]);
    std::string f;
    std::size_t j = 0;
    while (std::getline(row, f, ',') && j < cols.size()) cols[j++].push_back(std::stod(f));
  }
  return cols;
}

}  // namespace

// ------------------------------------------------------------------------------ bad scenario

// `scole-identify ... | head -c 1`: the reader goes away after one byte; the run still finishes,
// commits its outputs and exits 0 (before: killed by SIGPIPE, exit 141, the staging left behind).
TEST(ScoleIdentifyCli, AReaderThatGoesAwayDoesNotLoseTheOutputs) {
  TempDir dir;
  std::signal(SIGPIPE, SIG_DFL);  // the default a shell gives a pipeline, whatever this process has
  const std::string cmd = "cd " + shell_quote(dir.path().string()) + " && bash -c " +
                          shell_quote(shell_quote(SCOLE_IDENTIFY_EXE) + " -s paper-beam-1 -o out 2> /dev/null | head -c 1 > /dev/null; "
                                      "exit ${PIPESTATUS[0]}");
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_TRUE(fs::exists(dir / "out" / "identify.json"));
  for (const auto& e : fs::directory_iterator(dir.path()))
    EXPECT_EQ(e.path().filename().string().find(".out.staging"), std::string::npos) << e.path() << " left behind";
}

TEST(ScoleIdentifyCli, UnknownBuiltinScenario) {
  TempDir dir;
  const fs::path out = dir / "out";
  const Result r = run({"--scenario", "paper-beam-9", "--out", out.string()}, dir);
  expect_input_error(r, out, {"scenario 'paper-beam-9'", "not a built-in scenario"});
}

TEST(ScoleIdentifyCli, MissingYamlFile) {
  TempDir dir;
  const fs::path out = dir / "out";
  const Result r = run({"--scenario", "/nonexistent/dir/s.yaml", "--out", out.string()}, dir);
  expect_input_error(r, out, {"'/nonexistent/dir/s.yaml'", "cannot be opened"});
}

TEST(ScoleIdentifyCli, MalformedYaml) {
  // Unterminated flow map.
  expect_yaml_error("name: broken\nbeam: {length: 10, EI: 5\nsensors: []\n", {"malformed YAML at line "});
}

TEST(ScoleIdentifyCli, NegativeStiffness) {
  expect_yaml_error(good_with("EI: 23000", "EI: -3"), {"beam.EI must be > 0, got -3"});
}

TEST(ScoleIdentifyCli, ZeroMassPerLength) {
  expect_yaml_error(good_with("rho_A: 67", "rho_A: 0"), {"beam.rho_A must be > 0, got 0"});
}

TEST(ScoleIdentifyCli, NanStiffness) {
  expect_yaml_error(good_with("EI: 23000", "EI: .nan"), {"beam.EI", ".nan"});
}

// Supports and attachments (docs/theory.md §2.5): one line naming the file, the field and the
// value, exit 2, nothing written; an estimate naming a quantity no element holds lists those that do.
TEST(ScoleIdentifyCli, SupportsAndAttachmentsBadInput) {
  expect_yaml_error(good_with("zeta: 0}", "zeta: 0, supports: {left: {k_theta: 500}}}"),
                    {"beam.supports.left.k_theta", "clamped end holds", "got 500"});
  expect_yaml_error(good_with("zeta: 0}", "zeta: 0, attachments: [{name: acc, location: 11, mass: 0.1}]}"),
                    {"beam.attachments[0].location", "got 11"});
  expect_yaml_error(good_with("zeta: 0}", "zeta: 0, attachments: [{name: acc, location: 5, mass: -2}]}"),
                    {"beam.attachments[0].mass", "got -2"});
  const std::string pinned = scoleid::test::replaced(
      good_with("left: clamped, right: free, rho_A: 67, EI: 23000, zeta: 0}",
                "left: pinned, right: free, rho_A: 67, EI: 23000, zeta: 0, supports: {left: {k_theta: 5.0e5}}}"),
      "estimate: [q1, q2]", "estimate: [q1, q2, supports.left.k_w]");
  expect_yaml_error(pinned, {"identification.estimate[2]", "supports.left.k_theta", "supports.left.k_w"});
}

TEST(ScoleIdentifyCli, SensorOutsideBeam) {
  expect_yaml_error(good_with("kind: displacement, location: 10", "kind: displacement, location: 12"),
                    {"sensors[0].location", "got 12"});
}

TEST(ScoleIdentifyCli, UnknownFieldTypo) {
  expect_yaml_error(good_with("length: 10", "lenght: 10"), {"beam.lenght", "is not a known field", "'lenght'"});
}

TEST(ScoleIdentifyCli, UnsupportedSensorKind) {
  expect_yaml_error(good_with("kind: displacement", "kind: line_of_sight"), {"sensors[0].kind", "'line_of_sight'"});
}

// ---------------------------------------------------------------------------------- bad data

TEST(ScoleIdentifyCli, UnsupportedScoleSensorKind) {
  // A line of sight is defined from the mast root to a mast or reflector point, not for the shuttle.
  expect_yaml_error(scoleid::test::test_scenario("cli_test/scole-los"),
                    {"sensors[0].kind", "'line_of_sight'"});
}

TEST(ScoleIdentifyCli, AccelerometerAndVelocitySensorsRecoverStiffnessMassAndDamping) {
  // A cantilever seen only through a tip accelerometer and a mid-span velocity sensor: EI, rho_A
  // and the Kelvin–Voigt c_kv from 13 %, 6 % and 36 % off, to the spatial bias of 20 elements
  // against 40. (At 10 elements c_kv's bias is 2.6e-3 with the damping-aware step of 2.1 ms; the
  // sample-interval step, 5 ms, hid it under a time error of the opposite sign: 8.2e-4.)
  TempDir dir;
  write_file(dir / "acc.yaml", scoleid::test::test_scenario("cli_test/acc-beam"));
  const Result r = run({"--scenario", (dir / "acc.yaml").string(), "--out", (dir / "out").string(), "-q"}, dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(dir / "out" / "identify.json"));
  for (const auto& p : j["parameters"]) {
    EXPECT_LT(std::abs(p["relative_error"].get<double>()), 2e-3) << p.dump();
    EXPECT_EQ(p["identifiable"], true) << p.dump();
  }
}

TEST(ScoleIdentifyCli, TheNonlinearModelIsUsedAndSaid) {
  // identification.model: nonlinear on a short slew (2 s, 4 elements): the run says which model it
  // used on stderr and in identify.json, recovers EI from its own nonlinear data, and gives std
  // from its Fisher matrix and an uncertainty interval that holds the error.
  TempDir dir;
  write_file(dir / "slew.yaml", scoleid::test::test_scenario("cli_test/short-slew"));
  const Result r = run({"--scenario", (dir / "slew.yaml").string(), "--out", (dir / "out").string(), "-q"}, dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("nonlinear model"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(slurp(dir / "out" / "identify.json"));
  EXPECT_EQ(j["model"], "nonlinear");
  EXPECT_EQ(j["settings"]["identification"]["model"], "nonlinear");
  const auto& p = j["parameters"][0];
  EXPECT_LT(std::abs(p["relative_error"].get<double>()), 1e-4) << p.dump();
  EXPECT_TRUE(p["std"].is_number()) << p.dump();
  ASSERT_TRUE(p["interval"].is_object()) << p.dump();
  EXPECT_LT(std::abs(p["estimate"].get<double>() - p["truth"].get<double>()), p["interval"]["half_width"].get<double>())
      << p.dump();
  EXPECT_EQ(p["interval"]["covers_truth"], true) << p.dump();
}

TEST(ScoleIdentifyCli, MissingDataFile) {
  TempDir dir;
  const fs::path out = dir / "out";
  fs::create_directories(out);
  const Result r =
      run({"--scenario", "paper-beam-1", "--data", "/nonexistent/truth.csv", "--out", out.string()}, dir);
  expect_input_error(r, out, {"data file '/nonexistent/truth.csv'", "cannot be opened"});
}

TEST(ScoleIdentifyCli, DataNonNumericValue) {
  expect_csv_error("truth.csv", "t,P,w_mid\n0,10,0\n0.01,10,abc\n0.02,10,1e-5\n",
                   {"line 3", "column 'w_mid'", "'abc'"});
}

TEST(ScoleIdentifyCli, DataNanValue) {
  expect_csv_error("truth.csv", "t,P,w_mid\n0,10,0\n0.01,10,nan\n0.02,10,1e-5\n",
                   {"line 3", "column 'w_mid'", "finite", "nan"});
}

TEST(ScoleIdentifyCli, DataTimeNotIncreasing) {
  expect_csv_error("truth.csv", "t,P,w_mid\n0,10,0\n0.01,10,1e-6\n0.01,10,2e-6\n0.03,10,3e-6\n",
                   {"line 4", "column 't'", "strictly increasing", "0.01"});
}

TEST(ScoleIdentifyCli, DataWithFewerThanThreeSamplesIsRefused) {
  // Two samples hold no fit to test and no half record to refit.
  expect_csv_error("truth.csv", "t,P,w_mid\n0,10,0\n0.01,10,1e-6\n", {"2 rows", "at least 3 samples"});
}

TEST(ScoleIdentifyCli, DataValuesBeyondTheMagnitudeLimitAreRefused) {
  expect_csv_error("truth.csv", "t,P,w_mid\n0,10,0\n0.01,10,1e300\n0.02,10,1e-5\n", {"line 3", "column 'w_mid'", "1e+300"});
}

TEST(ScoleIdentifyCli, ATimeSpanBeyondTheStepLimitIsRefusedBeforeAnySolve) {
  // A last time of 1e20 s (a typo in the time column) would mean 1e22 identifier steps.
  expect_csv_error("truth.csv", "t,P,w_mid\n0,10,0\n0.01,10,1e-6\n0.02,10,2e-6\n1e20,10,3e-6\n",
                   {"column t spans 1e+20 s", "limit"});
}

TEST(ScoleIdentifyCli, ARecordInWhichNoSensorMovesIsRefused) {
  expect_csv_error("truth.csv", "t,P,w_mid\n0,10,0\n0.01,10,0\n0.02,10,0\n0.03,10,0\n", {"every sensor's column is zero"});
  expect_yaml_error(good_with("amplitude: 10", "amplitude: 0"), {"sensors", "record nothing"});
}

TEST(ScoleIdentifyCli, AKeyWithoutAValueAndASecondDocumentAreRefused) {
  expect_yaml_error(good_with("location: 10}\nsimulation", "location: ~}\nsimulation"), {"sensors[0].location", "has no value"});
  expect_yaml_error(std::string(kGood) + "---\nname: second\n", {"2 YAML documents"});
  // A trailing `---` opens no second scenario: the file still reaches the run (here refused for
  // an unrelated field, to stop before any work).
  expect_yaml_error(good_with("  elements: 10\n", "  elements: 10\n  rtol: 10\n") + "---\n", {"identification.rtol"});
}

TEST(ScoleIdentifyCli, RelativeToleranceOutsideZeroOneIsRefused) {
  expect_yaml_error(good_with("  elements: 10\n", "  elements: 10\n  rtol: 10\n"), {"identification.rtol", "(0, 1)", "10"});
}

TEST(ScoleIdentifyCli, SteepestWeightsOfTheWrongCountAreTheOnlyLine) {
  expect_yaml_error(good_with("  elements: 10\n", "  elements: 10\n  steepest_weights: [1, 1, 1]\n"),
                    {"identification.steepest_weights", "one weight per estimated parameter (2)", "3 values"});
}

TEST(ScoleIdentifyCli, AnInertiaNoRigidBodyHasIsRefused) {
  expect_yaml_error(scoleid::test::test_scenario("cli_test/bad-shuttle"),
                    {"scole.shuttle", "triangle inequality", "Izz 100"});
}

TEST(ScoleIdentifyCli, AnEmptyPathOptionIsRefused) {
  TempDir dir;
  const fs::path out = dir / "out";
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--scenario", "paper-beam-1", "--data", "", "--out", out.string(), "-q"},
        std::vector<std::string>{"--scenario", "paper-beam-1", "--out", "", "-q"}}) {
    const Result r = run(args, dir);
    expect_input_error(r, out, {"is empty"});
  }
  EXPECT_FALSE(fs::exists(dir / "run")) << "an empty --out fell back to the default directory";
}

TEST(ScoleIdentifyCli, DataLineEndingsAndAByteOrderMark) {
  // CR alone ends no line for the reader: said, not misread as one long header.
  expect_csv_error("truth.csv", "t,P,w_mid\r0,10,0\r0.01,10,1e-6\r0.02,10,2e-6\r", {"line 1", "CR alone"});
  // A spreadsheet's byte-order mark is dropped: the header reads 't' and the rows are reached
  // (here to be refused for holding no response).
  expect_csv_error("truth.csv", "\xEF\xBB\xBFt,P,w_mid\n0,10,0\n0.01,10,0\n0.02,10,0\n", {"every sensor's column is zero"});
  // … also before a comment line; and CR CR LF endings (written by some CSV writers) read as lines.
  expect_csv_error("truth.csv", "\xEF\xBB\xBF# exported\nt,P,w_mid\n0,10,0\n0.01,10,0\n0.02,10,0\n",
                   {"every sensor's column is zero"});
  expect_csv_error("truth.csv", "t,P,w_mid\r\r\n0,10,0\r\r\n0.01,10,0\r\r\n0.02,10,0\r\r\n", {"every sensor's column is zero"});
}

TEST(ScoleIdentifyCli, DataLacksSensorColumn) {
  expect_csv_error("truth.csv", "t,P,other\n0,10,0\n0.01,10,1e-6\n0.02,10,2e-6\n", {"sensor 'w_mid'"});
}

// ------------------------------------------------------------------------------ command line

TEST(ScoleIdentifyCli, UnknownOption) {
  TempDir dir;
  const fs::path out = dir / "out";
  const Result r = run({"--bogus-option", "--out", out.string()}, dir);
  expect_input_error(r, out, {"--bogus-option"}, /*prefixed=*/false);
}

TEST(ScoleIdentifyCli, BadMethod) {
  TempDir dir;
  const fs::path out = dir / "out";
  const Result r = run({"--method", "newton-raphson", "--out", out.string()}, dir);
  expect_input_error(r, out, {"--method", "newton-raphson"}, /*prefixed=*/false);
}

// ---------------------------------------------------------------------------- positive paths

TEST(ScoleIdentifyCli, ListScenarios) {
  TempDir dir;
  const Result r = run({"--list-scenarios"}, dir);
  EXPECT_EQ(r.code, 0) << r.err;
  for (const char* n : {"paper-beam-1", "paper-beam-2", "paper-beam-3"})
    EXPECT_NE(r.out.find(n), std::string::npos) << n << " not listed:\n" << r.out;
}

TEST(ScoleIdentifyCli, Help) {
  TempDir dir;
  const Result r = run({"--help"}, dir);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("--data"), std::string::npos) << r.out;
}

TEST(ScoleIdentifyCli, GoodRunSyntheticThenWithData) {
  TempDir dir;
  const fs::path yaml = dir / "good.yaml", out1 = dir / "run1", out2 = dir / "run2";
  write_file(yaml, kGood);

  // 1. Synthetic data.
  const Result r1 = run({"--scenario", yaml.string(), "--out", out1.string(), "-q"}, dir);
  ASSERT_EQ(r1.code, 0) << "stderr:\n" << r1.err << "stdout:\n" << r1.out;
  ASSERT_TRUE(fs::exists(out1 / "identify.json"));
  ASSERT_TRUE(fs::exists(out1 / "fit.csv"));
  for (const auto& e : fs::directory_iterator(out1))
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
  nlohmann::json j1;
  ASSERT_NO_THROW(j1 = nlohmann::json::parse(slurp(out1 / "identify.json")));
  for (const char* k : {"parameters", "iterations", "termination", "gradient_evaluations", "forward_solves", "wall_seconds"})
    EXPECT_TRUE(j1.contains(k)) << "identify.json lacks '" << k << "'";
  ASSERT_TRUE(j1["parameters"].is_array());
  ASSERT_EQ(j1["parameters"].size(), 2u);
  std::map<std::string, double> truth;
  for (const auto& p : j1["parameters"]) {
    for (const char* k : {"name", "initial", "estimate", "truth", "std"})
      EXPECT_TRUE(p.contains(k)) << "parameter lacks '" << k << "': " << p.dump();
    if (!p.contains("name") || !p.contains("estimate") || !p.contains("truth")) continue;
    const std::string name = p["name"].get<std::string>();
    const double est = p["estimate"].get<double>(), tru = p["truth"].get<double>();
    truth[name] = tru;
    EXPECT_LT(std::abs(est / tru - 1.0), 1e-3) << name << ": estimate " << est << ", truth " << tru;
  }
  EXPECT_EQ(j1["parameters"][0].value("name", ""), "q1");
  EXPECT_EQ(j1["parameters"][1].value("name", ""), "q2");

  // 2. The measured column of fit.csv as a data file t,w_tip; no truth.json beside it.
  std::vector<std::string> header;
  const auto cols = csv_columns(slurp(out1 / "fit.csv"), header);
  int jt = -1, jm = -1;
  for (std::size_t k = 0; k < header.size(); ++k) {
    if (header[k] == "t") jt = static_cast<int>(k);
    if (header[k] == "w_tip_measured") jm = static_cast<int>(k);
  }
  ASSERT_GE(jt, 0) << "fit.csv has no t column";
  ASSERT_GE(jm, 0) << "fit.csv has no w_tip_measured column";
  ASSERT_GT(cols[static_cast<std::size_t>(jt)].size(), 100u);
  fs::create_directories(dir / "data");
  const fs::path csv = dir / "data" / "measured.csv";
  {
    std::ostringstream os;
    os.precision(17);
    os << "t,w_tip\n";
    for (std::size_t i = 0; i < cols[static_cast<std::size_t>(jt)].size(); ++i)
      os << cols[static_cast<std::size_t>(jt)][i] << ',' << cols[static_cast<std::size_t>(jm)][i] << '\n';
    write_file(csv, os.str());
  }
  const Result r2 = run({"--scenario", yaml.string(), "--data", csv.string(), "--out", out2.string(), "-q"}, dir);
  ASSERT_EQ(r2.code, 0) << "stderr:\n" << r2.err << "stdout:\n" << r2.out;
  nlohmann::json j2;
  ASSERT_NO_THROW(j2 = nlohmann::json::parse(slurp(out2 / "identify.json")));
  ASSERT_TRUE(j2.contains("parameters"));
  ASSERT_EQ(j2["parameters"].size(), 2u);
  for (const auto& p : j2["parameters"]) {
    const std::string name = p.value("name", "");
    ASSERT_TRUE(truth.count(name)) << name;
    const double est = p.value("estimate", std::nan(""));
    EXPECT_LT(std::abs(est / truth[name] - 1.0), 1e-3) << name << ": estimate " << est << ", truth " << truth[name];
  }
}

// ------------------------------------------------------------------------------- hardening
// Each finding of a hostile-but-fair review, reproduced end to end.

namespace {
bool have_gnuplot() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

nlohmann::json read_json_file(const fs::path& p) { return nlohmann::json::parse(slurp(p)); }

// Starts scole-identify with `args` in `dir`, sends `sig` after `delay` seconds, returns the
// exit code (or -1); `after`, if given, receives the seconds from the signal to the exit.
int run_and_signal(const std::vector<std::string>& args, const TempDir& dir, double delay, int sig,
                   double* after = nullptr) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(dir.path().c_str()) != 0) ::_exit(99);
    std::FILE* devnull = std::fopen("/dev/null", "w");
    if (devnull) {
      ::dup2(fileno(devnull), 1);
      ::dup2(fileno(devnull), 2);
    }
    std::vector<char*> argv{const_cast<char*>(SCOLE_IDENTIFY_EXE)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(SCOLE_IDENTIFY_EXE, argv.data());
    ::_exit(98);
  }
  ::usleep(static_cast<useconds_t>(delay * 1e6));
  ::kill(pid, sig);
  const auto t0 = std::chrono::steady_clock::now();
  int status = 0;
  ::waitpid(pid, &status, 0);
  if (after) *after = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Only `keep` in `dir` (no staging directory, no temporary file).
void expect_only(const fs::path& dir, const std::vector<std::string>& keep) {
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    EXPECT_NE(std::find(keep.begin(), keep.end(), n), keep.end()) << "left behind: " << e.path();
  }
}
}  // namespace

TEST(ScoleIdentifyHardening, OutDirectoryWithQuotesAndSemicolonsRunsNothingAndStillPlots) {
  TempDir dir;
  write_file(dir / "good.yaml", kGood);
  const fs::path out = dir / "mast's runs; touch pwned; '";
  const Result r = run({"--scenario", (dir / "good.yaml").string(), "--out", out.string(), "-q"}, dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir / "pwned")) << "the --out text ran a command";
  EXPECT_TRUE(fs::exists(out / "identify.json"));
  if (have_gnuplot()) {
    EXPECT_TRUE(fs::exists(out / "fit.png")) << "no plot in a directory whose name holds a quote";
  }
}

TEST(ScoleIdentifyHardening, SensorNameWithShellOrGnuplotSyntaxIsRefused) {
  expect_yaml_error(good_with("name: w_tip", "name: \"w'; print system(\\\"touch pwned\\\"); #\""),
                    {"sensors[0].name", "[A-Za-z0-9_.-]"});
}

TEST(ScoleIdentifyHardening, NotConvergedExitsOneWithOutputsMarked) {
  TempDir dir;
  write_file(dir / "good.yaml", kGood);
  const fs::path out = dir / "out";
  const Result r = run({"--scenario", (dir / "good.yaml").string(), "--out", out.string(), "-q", "--max-iterations", "1"}, dir);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("did not converge"), std::string::npos) << r.err;
  ASSERT_TRUE(fs::exists(out / "identify.json"));
  EXPECT_EQ(read_json_file(out / "identify.json").value("converged", true), false);
}

// The exit code follows "converged" whatever made it false: here the optimiser converges and the
// fit explains the data, but no smoothness weight meets the discrepancy principle (the attainable
// data misfit of this noise draw lies above the noise band; docs/theory.md §7.8).
TEST(ScoleIdentifyHardening, AnUnmetDiscrepancyPrincipleExitsOne) {
  TempDir dir;
  write_file(dir / "band.yaml", scoleid::test::test_scenario("cli_test/discrepancy-not-met"));
  const fs::path out = dir / "out";
  const Result r = run({"--scenario", (dir / "band.yaml").string(), "--out", out.string(), "-q"}, dir);
  ASSERT_TRUE(fs::exists(out / "identify.json")) << r.err;
  const auto j = read_json_file(out / "identify.json");
  // The case's premise: optimiser converged, fit within the band, principle not met.
  ASSERT_TRUE(j.value("optimizer_converged", false)) << j.dump();
  ASSERT_TRUE(j["fit_test"].value("explains_data", false)) << j["fit_test"].dump();
  ASSERT_FALSE(j["smoothness"].value("discrepancy_met", true)) << j["smoothness"].dump();
  EXPECT_FALSE(j.value("converged", true));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("discrepancy principle not met"), std::string::npos) << r.err;
  // The path stops where the misfit levels off above the target (docs/theory.md §7.8): its last
  // decade's drop, smaller than the one before, repeated at every decade left down to 1e-10 would
  // not reach the expected misfit; every earlier weight would have (so the path is not cut short
  // of a weight that could meet it), and the last weight is the one kept.
  const auto& path = j["smoothness"]["path"];
  ASSERT_GE(path.size(), 3u);
  EXPECT_LT(path.size(), 11u) << j["smoothness"].dump();
  const double expected = j["smoothness"]["expected_misfit"].get<double>();
  const auto reaches = [&](std::size_t k) {
    const double drop = path[k - 1]["data_misfit"].get<double>() - path[k]["data_misfit"].get<double>();
    return path[k]["data_misfit"].get<double>() - drop * std::log10(path[k]["weight"].get<double>() / 1e-10) <=
           expected;
  };
  const std::size_t last = path.size() - 1;
  EXPECT_FALSE(reaches(last));
  for (std::size_t k = 2; k < last; ++k) {
    const double drop_k = path[k - 1]["data_misfit"].get<double>() - path[k]["data_misfit"].get<double>();
    const double drop_before = path[k - 2]["data_misfit"].get<double>() - path[k - 1]["data_misfit"].get<double>();
    EXPECT_TRUE(reaches(k) || drop_k >= drop_before) << "the path went on past weight " << path[k]["weight"];
  }
  EXPECT_EQ(j["smoothness"]["weight"].get<double>(), path[last]["weight"].get<double>());
  // No restart follows (docs/theory.md §7.6): the optimiser converged and the model explains the
  // data, so a restart would keep the weight and refit the same minimum; and with a prior in force
  // the smoothed restart, which looks for a sawtooth, is not run either.
  EXPECT_EQ(j["attempts"].size(), 1u) << j["attempts"].dump();
}

// A run whose every parameter is flagged says so in words and earns no "converged": EI on two
// halves seen from midspan, where a profile and its mirror fit alike. A sensor on a support, whose
// record is noise alone, is refused before any work.
TEST(ScoleIdentifyHardening, ARunWithNoIdentifiableParameterSaysSo) {
  TempDir dir;
  write_file(dir / "mirror.yaml", scoleid::test::test_scenario("cli_test/mirror-profile"));
  const fs::path out = dir / "out";
  const Result r = run({"--scenario", (dir / "mirror.yaml").string(), "--out", out.string(), "-q"}, dir);
  ASSERT_TRUE(fs::exists(out / "identify.json")) << r.err;
  const auto j = read_json_file(out / "identify.json");
  for (const auto& p : j["parameters"]) EXPECT_FALSE(p.value("identifiable", true)) << p.dump();
  EXPECT_NE(r.err.find("none of the 2 estimated parameters is identifiable"), std::string::npos) << r.err;
  // The estimate is the start's or the mirror's, not the data's: no "converged", exit 1.
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_FALSE(j["converged"].get<bool>());
  EXPECT_NE(r.err.find("the data determine none of the 2 estimated parameters"), std::string::npos) << r.err;
  write_file(dir / "support.yaml", scoleid::test::test_scenario("cli_test/sensor-on-support"));
  const Result s = run({"--scenario", (dir / "support.yaml").string(), "--out", (dir / "out2").string(), "-q"}, dir);
  expect_input_error(s, dir / "out2", {"sensors[0].noise_std buries every sensor's signal"});
}

TEST(ScoleIdentifyHardening, NegativeMaxIterationsIsRefused) {
  TempDir dir;
  const fs::path out = dir / "out";
  const Result r = run({"--scenario", "paper-beam-1", "--out", out.string(), "--max-iterations", "-5"}, dir);
  expect_input_error(r, out, {"--max-iterations", "-5"}, /*prefixed=*/false);
}

TEST(ScoleIdentifyHardening, TimeStepThatCannotResolveTheModesIsRefused) {
  expect_yaml_error(good_with("elements: 10", "elements: 10\n  time_step: 5"),
                    {"identification.time_step", "must resolve flexible mode 4", "got 5"});
}

TEST(ScoleIdentifyHardening, SizesAreBoundedBeforeAnyWork) {
  expect_yaml_error(good_with("elements: 10", "elements: 10\n  time_step: 1e-12"), {"identification.time_step", "steps", "1e-12"});
  expect_yaml_error(good_with("duration: 2", "duration: 1e9"), {"simulation.sample_interval", "samples", "limit"});
  expect_yaml_error(good_with("EI: 23000", "EI: 1e300"), {"beam.EI", "magnitude", "1e+300"});
  expect_yaml_error(good_with("amplitude: 10", "amplitude: 1e308"), {"inputs[0].signal.amplitude", "magnitude"});
}

TEST(ScoleIdentifyHardening, DuplicateKeysAndInvalidUtf8AreRefused) {
  expect_yaml_error(good_with("rho_A: 67,", "rho_A: 67, rho_A: 70,"), {"beam.rho_A appears more than once"});
  expect_yaml_error(std::string(kGood) + "description: \"\\N\"\n", {"description", "UTF-8"});
}

TEST(ScoleIdentifyHardening, UnwritableOutIsReportedBeforeTheRun) {
  TempDir dir;
  write_file(dir / "file", "x");
  const fs::path out = dir / "file" / "out";
  const Result r = run({"--scenario", "paper-beam-1", "--out", out.string()}, dir);
  // One line (the run's own progress line never appears): checked before any work.
  expect_input_error(r, out, {"output directory", "file/out"});
}

TEST(ScoleIdentifyHardening, ForeignFilesInOutAreNeitherReplacedNorMixed) {
  TempDir dir;
  const fs::path out = dir / "out";
  fs::create_directories(out);
  write_file(out / "notes.txt", "mine");
  const Result r = run({"--scenario", "paper-beam-1", "--out", out.string()}, dir);
  expect_input_error(r, out, {"output directory", "notes.txt"});
  EXPECT_EQ(slurp(out / "notes.txt"), "mine");
}

TEST(ScoleIdentifyHardening, EarlierRunIsReplacedWholeOrKept) {
  TempDir dir;
  write_file(dir / "good.yaml", kGood);
  const fs::path out = dir / "out";
  ASSERT_EQ(run({"--scenario", (dir / "good.yaml").string(), "--out", out.string(), "-q"}, dir).code, 0);
  const std::string first = slurp(out / "identify.json");
  // A failing run (bad data) leaves the earlier run exactly as it was.
  write_file(dir / "bad.csv", "t,w_tip\n0,0\n0.01,nan\n");
  const Result bad = run({"--scenario", (dir / "good.yaml").string(), "--data", (dir / "bad.csv").string(), "--out",
                          out.string(), "-q"}, dir);
  EXPECT_EQ(bad.code, 2);
  EXPECT_EQ(slurp(out / "identify.json"), first);
  expect_only(dir.path(), {"good.yaml", "bad.csv", "out", "stderr.txt"});
}

// What an interrupted run leaves (RunOptions::keep_interrupted): before the first iterate nothing;
// once the optimiser has an iterate, a complete run — every output, the last iterate as the
// estimate, "termination": "interrupted", "converged": false, the signal named — and never half a
// run. Either way within a second of the signal, exit 128 + signal.
void expect_interrupted_run(const fs::path& dir, const fs::path& out, const std::string& signal, bool written) {
  if (!written) {
    EXPECT_FALSE(fs::exists(out)) << "outputs of a run interrupted before its first iterate";
    expect_only(dir, {"stderr.txt"});
    return;
  }
  for (const char* f : {"identify.json", "fit.csv", "fit.gp", "spectrum.csv", "spectrum.gp"}) EXPECT_TRUE(fs::exists(out / f)) << f;
  const auto j = read_json_file(out / "identify.json");
  EXPECT_EQ(j.value("termination", ""), "interrupted");
  EXPECT_EQ(j.value("converged", true), false);
  ASSERT_TRUE(j.contains("interrupted")) << j.dump().substr(0, 400);
  EXPECT_EQ(j["interrupted"].value("signal", ""), signal);
  EXPECT_EQ(j["interrupted"].value("note", "").rfind(signal + " at iteration ", 0), 0u) << j["interrupted"].dump();
  int finite = 0;
  for (const auto& p : j["parameters"]) finite += p["estimate"].is_number() && std::isfinite(p["estimate"].get<double>());
  EXPECT_EQ(finite, static_cast<int>(j["parameters"].size()));
  expect_only(dir, {"out", "stderr.txt"});
}

TEST(ScoleIdentifyHardening, SigtermAndSigintKeepTheLastIterateAsACompleteRunOrLeaveNothing) {
  for (const int sig : {SIGTERM, SIGINT}) {
    // beam-ei8 takes about 6 s: at 0.3 s it is still synthesising its data (no iterate), at 2.5 s
    // it is iterating (the first iterate comes at about 1 s on an idle machine).
    for (const double delay : {0.3, 2.5}) {
      TempDir dir;
      const fs::path out = dir / "out";
      double after = 0.0;
      const int code = run_and_signal({"--scenario", "beam-ei8", "--out", out.string(), "-q"}, dir, delay, sig, &after);
      std::printf("  signal %d at %.2f s: exit %d, %.2f s after it, outputs %s\n", sig, delay, code, after,
                  fs::exists(out) ? "written" : "none");
      EXPECT_EQ(code, 128 + sig);
      EXPECT_LT(after, 1.0);
      // On a loaded machine the signal meant for 0.3 s can land after the first iterate: then the
      // run must be a complete interrupted one; either way, nothing half-written.
      expect_interrupted_run(dir.path(), out, sig == SIGTERM ? "SIGTERM" : "SIGINT", fs::exists(out));
    }
  }
}

// --max-wall-time: the same as a signal, exit 1 (a limit the user set, not an interruption), the
// limit named; and a limit reached before the first iterate writes nothing, exit 1.
// (frame-4storey: its first iterate within about 1.5 s, the whole run about 14 s on an idle
// machine; beam-ei8, 2.4 s in all, could end before a 2.5 s limit.)
TEST(ScoleIdentifyHardening, TheWallTimeLimitKeepsTheLastIterateOrSaysThereWasNone) {
  for (const std::string limit : {"0.05", "5"}) {
    TempDir dir;
    const fs::path out = dir / "out";
    const auto t0 = std::chrono::steady_clock::now();
    const Result r = run({"--scenario", "frame-4storey", "--out", out.string(), "-q", "--max-wall-time", limit}, dir);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("  --max-wall-time %s: exit %d after %.2f s, outputs %s\n", limit.c_str(), r.code, wall, fs::exists(out) ? "written" : "none");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_LT(wall, std::stod(limit) + 1.5);
    if (!fs::exists(out)) {
      EXPECT_NE(r.err.find("stopped at the wall-time limit (--max-wall-time) before the first iterate; no output written"), std::string::npos) << r.err;
      if (limit == "0.05") continue;
    }
    ASSERT_TRUE(fs::exists(out)) << r.err;
    EXPECT_NE(r.err.find("the wall-time limit at iteration "), std::string::npos) << r.err;
    const auto j = read_json_file(out / "identify.json");
    EXPECT_EQ(j.value("termination", ""), "interrupted");
    EXPECT_EQ(j.value("converged", true), false);
    EXPECT_EQ(j["interrupted"].value("signal", ""), "wall-time limit");
  }
  // A run that ends before its limit is the run it always was.
  TempDir dir;
  const Result r = run({"--scenario", "paper-beam-1", "--out", (dir / "out").string(), "-q", "--max-wall-time", "600"}, dir);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(read_json_file(dir / "out" / "identify.json").contains("interrupted"));
}

TEST(ScoleIdentifyHardening, ASignalEndsANonlinearRunWithinItsSolveNotAfterIt) {
  // The nonlinear model's solves take seconds each (synthesising the data on 20 elements, then
  // every cost, gradient and differenced sensitivity); a signal is honoured between samples of a
  // forward solve and of a costate, not at the next iteration.
  TempDir dir;
  const fs::path out = dir / "out";
  for (const double delay : {1.0, 6.0}) {
    double after = 0.0;
    const int code = run_and_signal({"--scenario", "scole-slew-case1", "--out", out.string(), "-q"}, dir, delay, SIGTERM,
                                    &after);
    std::printf("  SIGTERM at %.0f s: exit %d, %.2f s after the signal\n", delay, code, after);
    EXPECT_EQ(code, 128 + SIGTERM);
    EXPECT_LT(after, 1.0);
    EXPECT_FALSE(fs::exists(out)) << "outputs of an interrupted run";
    expect_only(dir.path(), {});
  }
}

TEST(ScoleIdentifyHardening, FlaggedParametersHaveNoStdAndNoStdMeansNotAssessed) {
  TempDir dir;
  const fs::path out = dir / "out", out2 = dir / "out2";
  // Dampers of 1e-6 lb s/ft on the free proof masses change the tip response by far less than
  // the identifier's own discretisation residual (at 1e-2 lb s/ft they are resolved to 3e-4).
  write_file(dir / "unseen.yaml", scoleid::test::test_scenario("cli_test/unseen-actuator-damper"));
  const Result r = run({"--scenario", (dir / "unseen.yaml").string(), "--out", out.string(), "-q"}, dir);
  ASSERT_TRUE(r.code == 0 || r.code == 1) << r.err;
  int flagged = 0;
  const auto j1 = read_json_file(out / "identify.json");
  for (const auto& p : j1["parameters"]) {
    if (p["identifiable"].is_boolean() && !p["identifiable"].get<bool>()) {
      ++flagged;
      EXPECT_TRUE(p["std"].is_null()) << p.dump();
      EXPECT_TRUE(p.contains("not_identifiable_because")) << p.dump();
    } else {
      EXPECT_TRUE(p["std"].is_number()) << p.dump();
    }
  }
  EXPECT_GE(flagged, 1) << "the actuator damper is not identifiable from these data";
  const Result r2 = run({"--scenario", "paper-beam-1", "--out", out2.string(), "-q", "--no-std"}, dir);
  ASSERT_EQ(r2.code, 0) << r2.err;
  const auto j = read_json_file(out2 / "identify.json");
  for (const auto& p : j["parameters"]) EXPECT_TRUE(p["identifiable"].is_null()) << p.dump();
  EXPECT_EQ(j["identifiability"].value("assessed", true), false);
}

TEST(ScoleIdentifyHardening, DataColumnsNoiseAndStaleMetadata) {
  TempDir dir;
  write_file(dir / "good.yaml", kGood);
  const fs::path out1 = dir / "run1";
  ASSERT_EQ(run({"--scenario", (dir / "good.yaml").string(), "--out", out1.string(), "-q"}, dir).code, 0);
  std::vector<std::string> header;
  const auto cols = csv_columns(slurp(out1 / "fit.csv"), header);
  const auto col = [&](const std::string& n) {
    const auto it = std::find(header.begin(), header.end(), n);
    return cols[static_cast<std::size_t>(it - header.begin())];
  };
  const auto t = col("t"), w = col("w_tip_measured");
  fs::create_directories(dir / "data");
  {
    std::ostringstream os;
    os.precision(17);
    os << "t,P,w_tip,spare\n";
    for (std::size_t i = 0; i < t.size(); ++i) os << t[i] << ",10," << w[i] << ",0\n";
    write_file(dir / "data" / "truth.csv", os.str());
  }
  const std::string csv = (dir / "data" / "truth.csv").string();
  // 1. Every column accounted for, in identify.json and on stderr.
  const fs::path out2 = dir / "run2";
  const Result r2 = run({"--scenario", (dir / "good.yaml").string(), "--data", csv, "--out", out2.string(), "-q"}, dir);
  ASSERT_EQ(r2.code, 0) << r2.err;
  EXPECT_NE(r2.err.find("unused spare"), std::string::npos) << r2.err;
  const auto j2 = read_json_file(out2 / "identify.json");
  EXPECT_EQ(j2["data_columns"]["unused"], nlohmann::json::array({"spare"}));
  EXPECT_EQ(j2["data_columns"]["inputs_from_data"], nlohmann::json::array({"P"}));
  EXPECT_TRUE(j2["data_columns"]["stepped_inputs"].empty());
  EXPECT_EQ(r2.err.find("jumps by"), std::string::npos) << r2.err;
  // 1b. An input column with a step inside the record: piecewise linear between samples, the step
  // is spread over a sample and may move by half of one; the run says so (stderr, identify.json).
  {
    std::ostringstream os;
    os.precision(17);
    os << "t,P,w_tip\n";
    const std::size_t mid = t.size() / 2;
    for (std::size_t i = 0; i < t.size(); ++i) os << t[i] << "," << (i < mid ? 0 : 10) << "," << w[i] << "\n";
    fs::create_directories(dir / "stepped");
    write_file(dir / "stepped" / "m.csv", os.str());
    const fs::path out = dir / "run-stepped";
    const Result r = run({"--scenario", (dir / "good.yaml").string(), "--data", (dir / "stepped" / "m.csv").string(), "--out",
                          out.string(), "-q", "--max-iterations", "0", "--no-std"},
                         dir);
    ASSERT_TRUE(r.code == 0 || r.code == 1) << r.err;
    EXPECT_NE(r.err.find("input 'P' from the data jumps by 10"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("signal_from: scenario"), std::string::npos) << r.err;
    const auto j = read_json_file(out / "identify.json");
    ASSERT_EQ(j["data_columns"]["stepped_inputs"].size(), 1u);
    const auto& st = j["data_columns"]["stepped_inputs"][0];
    EXPECT_EQ(st["name"], "P");
    EXPECT_DOUBLE_EQ(st["largest_jump"].get<double>(), 10.0);
    EXPECT_DOUBLE_EQ(st["at"].get<double>(), t[mid]);
    EXPECT_NEAR(st["switch_shift_up_to"].get<double>(), 0.5 * (t[mid] - t[mid - 1]), 1e-12);
    EXPECT_TRUE(st["scenario_gives_signal"].get<bool>());
  }
  // 2. An input declared to come from the data, absent from it: refused.
  write_file(dir / "from_data.yaml", good_with("location: 10, signal:", "location: 10, signal_from: data, signal:"));
  {
    std::ostringstream os;
    os.precision(17);
    os << "t,w_tip\n";
    for (std::size_t i = 0; i < t.size(); ++i) os << t[i] << "," << w[i] << "\n";
    fs::create_directories(dir / "nop");
    write_file(dir / "nop" / "m.csv", os.str());
  }
  const Result r3 = run({"--scenario", (dir / "from_data.yaml").string(), "--data", (dir / "nop" / "m.csv").string(),
                         "--out", (dir / "run3").string(), "-q"}, dir);
  expect_input_error(r3, dir / "run3", {"no column for input 'P'", "signal_from is data"});
  // 3. truth.json's noise levels are used; a truth.json of another run is refused.
  nlohmann::json meta = {{"scenario", "cli-good"},
                         {"columns", {{{"name", "P"}, {"kind", "input"}, {"quantity", "force"}},
                                      {{"name", "w_tip"}, {"kind", "output"}, {"quantity", "displacement"}, {"noise_std", 1e-7}},
                                      {{"name", "spare"}, {"kind", "output"}, {"quantity", "displacement"}}}},
                         {"true_parameters", {{"rho_A", 67}, {"EI", 23000}, {"zeta", 0}, {"c_kv", 0}}}};
  write_file(dir / "data" / "truth.json", meta.dump());
  const fs::path out4 = dir / "run4";
  const Result r4 = run({"--scenario", (dir / "good.yaml").string(), "--data", csv, "--out", out4.string(), "-q"}, dir);
  ASSERT_EQ(r4.code, 0) << r4.err;
  const auto j4 = read_json_file(out4 / "identify.json");
  EXPECT_EQ(j4["identifiability"]["noise_source"], "truth.json");
  // (the stated level, as a band chosen from the record passes it: σ √g)
  const double gain = j4["band"].is_object() && j4["band"].contains("noise_gain") ? j4["band"]["noise_gain"].get<double>() : 1.0;
  EXPECT_DOUBLE_EQ(j4["identifiability"]["noise_std"][0].get<double>(), 1e-7 * std::sqrt(gain));
  meta["columns"][2]["name"] = "other";
  write_file(dir / "data" / "truth.json", meta.dump());
  const Result r5 = run({"--scenario", (dir / "good.yaml").string(), "--data", csv, "--out", (dir / "run5").string(), "-q"}, dir);
  expect_input_error(r5, dir / "run5", {"truth.json", "not from the same run"});
  meta["columns"][2]["name"] = "spare";
  // 4. A truth.json of another structure, or placing a sensor on another body, is refused naming both.
  auto refused = [&](nlohmann::json m, const std::string& run_name, const std::vector<std::string>& words) {
    write_file(dir / "data" / "truth.json", m.dump());
    const Result r = run({"--scenario", (dir / "good.yaml").string(), "--data", csv, "--out", (dir / run_name).string(), "-q"}, dir);
    expect_input_error(r, dir / run_name, words);
  };
  nlohmann::json other = meta;
  other["structure"] = "scole";
  refused(other, "run6", {"truth.json", "structure 'scole'", "'beam'"});
  other = meta;
  other["columns"][1]["at"] = "mast";
  refused(other, "run7", {"truth.json", "column 'w_tip' is at the mast", "at the beam"});
  other = meta;
  other["columns"][0]["quantity"] = "moment";
  refused(other, "run8", {"truth.json", "column 'P' is a moment", "a force"});
  // 5. The unit truth.json states for a column its file gives none is the column's: values written
  // in mm are converted into the scenario's m (scale 1e-3 in identify.json), not read as metres.
  other = meta;
  other["columns"][1]["unit"] = "mm";
  write_file(dir / "data" / "truth.json", other.dump());
  write_file(dir / "in_m.yaml", good_with("kind: displacement, location: 10}", "kind: displacement, location: 10, unit: m}"));
  const fs::path out9 = dir / "run9";
  const Result r9 = run({"--scenario", (dir / "in_m.yaml").string(), "--data", csv, "--out", out9.string(), "-q",
                         "--max-iterations", "0", "--no-std"},
                        dir);
  ASSERT_TRUE(r9.code == 0 || r9.code == 1) << r9.err;
  bool found = false;
  const auto j9 = read_json_file(out9 / "identify.json");
  for (const auto& src : j9["data_columns"]["sources"])
    if (src["name"] == "w_tip") {
      found = true;
      EXPECT_EQ(src["column_unit"], "mm");
      EXPECT_EQ(src["unit_stated_by"], "truth.json");
      EXPECT_NEAR(src["scale"].get<double>(), 1e-3, 1e-15);
    }
  EXPECT_TRUE(found) << j9.dump() << r9.err;
  // 6. One sample of a sensor's column a thousand times the RMS of the others (a unit slip in one
  // row): refused, naming the column and the sample's time.
  fs::remove(dir / "data" / "truth.json");
  {
    std::ostringstream os;
    os.precision(17);
    os << "t,P,w_tip\n";
    for (std::size_t i = 0; i < t.size(); ++i) os << t[i] << ",10," << (i == 57 ? 1e23 : w[i]) << "\n";
    fs::create_directories(dir / "spike");
    write_file(dir / "spike" / "m.csv", os.str());
  }
  const Result r11 = run({"--scenario", (dir / "good.yaml").string(), "--data", (dir / "spike" / "m.csv").string(),
                          "--out", (dir / "run11").string(), "-q"},
                         dir);
  std::ostringstream at;
  at << "t = " << scoleid::io::format_value(t[57]) << " s is 1e+23";
  expect_input_error(r11, dir / "run11", {"column 'w_tip'", at.str(), "1000 times the RMS"});
}

TEST(ScoleIdentifyHardening, ATruthJsonWithARepeatedKeyIsRefusedNamingIt) {
  // {"scenario": "a", ..., "scenario": "b"}: nlohmann would keep the last; refused, naming the key.
  TempDir dir;
  write_file(dir / "good.yaml", kGood);
  fs::create_directories(dir / "data");
  write_file(dir / "data" / "truth.csv", "t,P,w_tip\n0,10,0\n0.01,10,1e-6\n0.02,10,2e-6\n");
  write_file(dir / "data" / "truth.json",
             R"({"scenario": "cli-good", "columns": [{"name": "P", "kind": "input", "kind": "output"}], "scenario": "x"})");
  const Result r = run({"--scenario", (dir / "good.yaml").string(), "--data", (dir / "data" / "truth.csv").string(), "--out",
                        (dir / "out").string(), "-q"}, dir);
  expect_input_error(r, dir / "out", {"truth.json", "columns[].kind", "appears more than once"});
}

TEST(ScoleIdentifyHardening, AnEndlessDeviceIsRefusedAndASignalWhileOpeningAFifoIsAnInterruption) {
  TempDir dir;
  // /dev/zero as the scenario: read up to the input-file limit, then one line, exit 2.
  const Result z = run({"--scenario", "/dev/zero", "--out", (dir / "out").string()}, dir);
  expect_input_error(z, dir / "out", {"scenario file '/dev/zero'", "limit"});
  // A FIFO no one writes to: the open blocks; SIGTERM ends the run as an interruption (143).
  const fs::path fifo = dir / "scenario.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  double after = 0.0;
  const int code = run_and_signal({"--scenario", fifo.string(), "--out", (dir / "out").string(), "-q"}, dir, 0.5, SIGTERM, &after);
  EXPECT_EQ(code, 128 + SIGTERM);
  EXPECT_LT(after, 1.0);
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(ScoleIdentifyCli, PrintScenarioRoundTripsEveryBuiltin) {
  TempDir dir;
  for (const auto& name : scoleid::io::builtin_scenario_names()) {
    const Result r = run({"--print-scenario", name}, dir);
    ASSERT_EQ(r.code, 0) << name << ": " << r.err;
    // Saved and loaded as a file, it is the built-in field for field.
    write_file(dir / "copy.yaml", r.out);
    nlohmann::json a = scoleid::io::to_json(scoleid::io::load_scenario((dir / "copy.yaml").string()));
    nlohmann::json b = scoleid::io::to_json(scoleid::io::load_scenario(name));
    a.erase("source");
    b.erase("source");
    EXPECT_EQ(a, b) << name;
  }
  const Result bad = run({"--print-scenario", "no-such"}, dir);
  EXPECT_EQ(bad.code, 2);
}

TEST(ScoleIdentifyCli, TruthOverridesShapeTheSyntheticDataAndTheReportedTruth) {
  // The truth's EI differs from the scenario's (the identifier's starting model): the synthetic
  // data come from the truth's structure, so q1 converges to the truth's EI / rho_A, and the
  // report compares against it.
  TempDir dir;
  write_file(dir / "o.yaml", std::string(kGood) + "truth:\n  overrides:\n    beam: {EI: 25000}\n");
  const Result r = run({"--scenario", (dir / "o.yaml").string(), "--out", (dir / "out").string(), "-q"}, dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(dir / "out" / "identify.json"));
  const auto& q1 = j["parameters"][0];
  EXPECT_NEAR(q1["truth"].get<double>(), 25000.0 / 67.0, 1e-9 * 25000.0 / 67.0);
  EXPECT_LT(std::abs(q1["relative_error"].get<double>()), 1e-3) << q1.dump();
  EXPECT_EQ(j["settings"]["truth"]["overrides"]["beam"]["EI"], nlohmann::json::array({25000.0}));
}

// ------------------------------------------------------------------------------ --experiments
// Two runs of kGood's cantilever (the second with its sensor at mid-span and a longer record) and
// measured modes: exit 0, the outputs of every experiment, shares summing to one; then the
// input-error contract for a run whose data file lacks its sensor column, a mode file with a
// negative frequency and one with a missing station value.
TEST(ScoleIdentifyExperiments, TwoRunsAndModesThenBadInput) {
  TempDir dir;
  write_file(dir / "a.yaml", kGood);
  write_file(dir / "b.yaml", good_with("{name: w_tip, at: beam, kind: displacement, location: 10}",
                                       "{name: w_mid, at: beam, kind: displacement, location: 5}"));
  write_file(dir / "e.yaml", "experiments: two\nruns:\n  - {name: a, scenario: a.yaml}\n  - {name: b, scenario: b.yaml}\n");
  const fs::path out = dir / "out";
  const Result r = run({"--experiments", (dir / "e.yaml").string(), "--out", out.string(), "-q", "--threads", "2"}, dir);
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  for (const char* f : {"identify.json", "fit-a.csv", "fit-b.csv", "fit-a.gp", "fit-b.gp"}) EXPECT_TRUE(fs::exists(out / f)) << f;
  const auto j = nlohmann::json::parse(slurp(out / "identify.json"));
  EXPECT_TRUE(j["converged"].get<bool>());
  ASSERT_EQ(j["per_experiment"].size(), 2u);
  double share = 0;
  for (const auto& e : j["per_experiment"]) share += e["misfit_share"].get<double>();
  EXPECT_NEAR(share, 1.0, 1e-12);
  for (const char* q : {"q1", "q2"})
    EXPECT_NEAR(j["estimate"][q].get<double>() / j["truth"][q].get<double>(), 1.0, 1e-3) << q;

  // A data file without the run's sensor column.
  write_file(dir / "a.csv", "t,P,w_other\n0,10,0\n0.01,10,1e-6\n0.02,10,2e-6\n");
  write_file(dir / "e2.yaml", "experiments: two\nruns:\n  - {name: a, scenario: a.yaml, data: a.csv}\n");
  const fs::path out2 = dir / "out2";
  expect_input_error(run({"--experiments", (dir / "e2.yaml").string(), "--out", out2.string(), "-q"}, dir), out2,
                     {"a.csv", "w_tip"});
  // Measured modes: a negative frequency, then a row short of a station value.
  write_file(dir / "m.csv", "mode,frequency_hz,frequency_std_hz,shape_std,w_tip\n1,-0.3,0.001,0.01,1\n");
  write_file(dir / "e3.yaml", "experiments: modes\nmodes: {file: m.csv, scenario: a.yaml}\n");
  const fs::path out3 = dir / "out3";
  expect_input_error(run({"--experiments", (dir / "e3.yaml").string(), "--out", out3.string(), "-q"}, dir), out3,
                     {"m.csv", "frequency_hz", "-0.3"});
  write_file(dir / "m.csv", "mode,frequency_hz,frequency_std_hz,shape_std,w_tip,w_mid\n1,0.3,0.001,0.01,1\n");
  expect_input_error(run({"--experiments", (dir / "e3.yaml").string(), "--out", out3.string(), "-q"}, dir), out3,
                     {"m.csv", "line 2"});
  // threads beyond the command line's bound of 1024: refused, naming the field.
  write_file(dir / "e5.yaml", "experiments: two\nthreads: 1000000\nruns:\n  - {name: a, scenario: a.yaml}\n");
  expect_input_error(run({"--experiments", (dir / "e5.yaml").string(), "--out", out3.string(), "-q"}, dir), out3,
                     {"e5.yaml", "threads", "1000000"});
  // A key given twice in the experiments file (yaml-cpp would answer the first): refused, naming it.
  write_file(dir / "e4.yaml", "experiments: two\nruns:\n  - {name: a, scenario: a.yaml, scenario: b.yaml}\n");
  expect_input_error(run({"--experiments", (dir / "e4.yaml").string(), "--out", out3.string(), "-q"}, dir), out3,
                     {"e4.yaml", "runs[0].scenario", "appears more than once"});

  // The cantilever's first two frequencies alone (closed form, f_k = λ_k² √(EI/ρA) / (2π L²)):
  // they fix q1 = EI/ρA and say nothing of q2 = 1/ρA, which the Fisher test flags.
  const double q1 = 23000.0 / 67.0, L = 10.0;
  char m[256];
  std::snprintf(m, sizeof m, "mode,frequency_hz,frequency_std_hz\n1,%.15g,1e-5\n2,%.15g,1e-4\n",
                std::pow(1.8751040687119611, 2) * std::sqrt(q1) / (2 * M_PI * L * L),
                std::pow(4.6940911329741745, 2) * std::sqrt(q1) / (2 * M_PI * L * L));
  write_file(dir / "m.csv", m);
  const fs::path out4 = dir / "out4";
  const Result rm = run({"--experiments", (dir / "e3.yaml").string(), "--out", out4.string(), "-q"}, dir);
  ASSERT_EQ(rm.code, 0) << rm.err << rm.out;
  const auto jm = nlohmann::json::parse(slurp(out4 / "identify.json"));
  EXPECT_EQ(jm["per_experiment"][0]["kind"], "modal");
  EXPECT_NEAR(jm["estimate"]["q1"].get<double>() / q1, 1.0, 1e-4);
  EXPECT_TRUE(jm["identifiability"]["identifiable"]["q1"].is_boolean());
  EXPECT_TRUE(jm["identifiability"]["identifiable"]["q2"].is_string()) << jm["identifiability"].dump();
  std::vector<std::string> header;
  const auto cols = csv_columns(slurp(out4 / "modes-fit.csv"), header);
  ASSERT_GE(header.size(), 4u);
  EXPECT_EQ(header[3], "model_mode");
  ASSERT_EQ(cols[3].size(), 2u);
  EXPECT_EQ(cols[3][0], 1.0);
  EXPECT_EQ(cols[3][1], 2.0);
}

// --export-model: the identified plant as JSON beside the run (its A has 2 x DOFs rows, its modal
// frequencies are the eigenvalues of A), a name that is no .json refused before any work.
TEST(ScoleIdentifyCli, ExportModelWritesThePlant) {
  TempDir dir;
  write_file(dir / "good.yaml", kGood);
  const Result r = run({"--scenario", "good.yaml", "--out", "out", "-q", "--export-model", "plant.json"}, dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(dir / "plant.json"));
  const auto& A = j["state_space"]["A"];
  const std::size_t n = A.size();
  ASSERT_GT(n, 0u);
  EXPECT_EQ(n % 2, 0u);
  EXPECT_EQ(A[0].size(), n);
  EXPECT_EQ(j["state_space"]["B"].size(), n);
  EXPECT_EQ(j["state_space"]["outputs"], nlohmann::json::array({"w_tip"}));
  EXPECT_EQ(j["modal"]["frequency_hz"].size(), n / 2);
  // The upper half of A is [0 I]: du/dt is the second half of the state.
  for (std::size_t i = 0; i < n / 2; ++i)
    for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(A[i][k].get<double>(), k == i + n / 2 ? 1.0 : 0.0);
  const Result bad = run({"--scenario", "good.yaml", "--out", "out2", "--export-model", "plant.txt"}, dir);
  expect_input_error(bad, dir / "out2", {"--export-model must name a .json or .mat file", "plant.txt"});
}

// An output file is never an input, never inside --out, never a directory, and its directory must
// take a file: each refused before any work (exit 2, nothing written, the input unchanged).
TEST(ScoleIdentifyHardening, ExportModelNeverOverwritesAnInputAndIsCheckedFirst) {
  TempDir dir;
  write_file(dir / "good.json", kGood);  // YAML is JSON's superset: a scenario named .json
  const std::string before = slurp(dir / "good.json");
  const Result a = run({"--scenario", "good.json", "--out", "out", "--export-model", "./good.json"}, dir);
  expect_input_error(a, dir / "out", {"--export-model './good.json'", "is an input of this run"});
  EXPECT_EQ(slurp(dir / "good.json"), before);
  fs::create_directories(dir / "out0");
  const Result b = run({"--scenario", "good.json", "--out", "out0", "--export-model", "out0/m.json"}, dir);
  EXPECT_EQ(b.code, 2) << b.err;
  EXPECT_NE(b.err.find("lies inside the output directory"), std::string::npos) << b.err;
  EXPECT_TRUE(fs::is_empty(dir / "out0"));
  fs::create_directories(dir / "m.json");
  const Result c = run({"--scenario", "good.json", "--out", "out", "--export-model", "m.json"}, dir);
  expect_input_error(c, dir / "out", {"--export-model 'm.json'", "is a directory"});
  // No staging file is left beside an export that was refused or failed.
  for (const auto& e : fs::directory_iterator(dir.path()))
    EXPECT_EQ(e.path().filename().string().find(".staging-"), std::string::npos) << e.path();
}

// One run per output directory: a second into the same directory, or into one inside it, is
// refused while the first holds it (here the test holds the lock as a running program would).
TEST(ScoleIdentifyHardening, ConcurrentRunsIntoOneOrNestedOutputDirectoriesAreRefused) {
  TempDir dir;
  write_file(dir / "good.yaml", kGood);
  const int fd = ::open((dir / ".out.lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  ASSERT_EQ(::write(fd, "scole-truth (pid 1)\n", 20), 20);
  const Result same = run({"--scenario", "good.yaml", "--out", "out", "-q"}, dir);
  expect_input_error(same, dir / "out", {"another run (scole-truth (pid 1)) is writing it"});
  const Result nested = run({"--scenario", "good.yaml", "--out", "out/inner", "-q"}, dir);
  EXPECT_EQ(nested.code, 2) << nested.err;
  EXPECT_NE(nested.err.find("lies inside"), std::string::npos) << nested.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "inner"));
  ::close(fd);
  const Result after = run({"--scenario", "good.yaml", "--out", "out", "-q"}, dir);
  EXPECT_EQ(after.code, 0) << after.err;
}

// A data file that is a FIFO no one writes to: SIGTERM is an interruption (143), not bad input.
TEST(ScoleIdentifyHardening, ASignalWhileOpeningAFifoAsDataIsAnInterruption) {
  TempDir dir;
  write_file(dir / "good.yaml", kGood);
  const fs::path fifo = dir / "data.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  double after = 0.0;
  const int code = run_and_signal({"--scenario", "good.yaml", "--data", fifo.string(), "--out", (dir / "out").string(), "-q"}, dir,
                                  0.5, SIGTERM, &after);
  EXPECT_EQ(code, 128 + SIGTERM);
  EXPECT_LT(after, 1.0);
  EXPECT_FALSE(fs::exists(dir / "out"));
}

// An input inside --out named like one of the run's outputs would be replaced with the directory:
// refused before any work, the input unchanged.
TEST(ScoleIdentifyHardening, AnInputInsideTheOutputDirectoryIsRefused) {
  TempDir dir;
  write_file(dir / "good.yaml", kGood);
  const Result first = run({"--scenario", "good.yaml", "--out", "q", "-q"}, dir);
  ASSERT_EQ(first.code, 0) << first.err;
  const std::string fit = slurp(dir / "q" / "fit.csv");
  const Result r = run({"--scenario", "good.yaml", "--data", "q/fit.csv", "--out", "q", "-q"}, dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("holds an input of this run ('q/fit.csv')"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir / "q" / "fit.csv"), fit);
}

// A FIFO whose writer sends a little and then stalls: the read blocks, and SIGTERM still ends the
// run within a second as an interruption (std::ifstream would retry the interrupted read for ever).
TEST(ScoleIdentifyHardening, ASignalDuringAStalledReadOfAFifoIsAnInterruption) {
  TempDir dir;
  write_file(dir / "good.yaml", kGood);
  const fs::path fifo = dir / "data.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const pid_t writer = ::fork();
  if (writer == 0) {
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    if (fd >= 0 && ::write(fd, "t,P,w_tip\n0,0,0\n", 16) == 16) ::sleep(30);
    ::_exit(0);
  }
  double after = 0.0;
  const int code = run_and_signal({"--scenario", "good.yaml", "--data", fifo.string(), "--out", (dir / "out").string(), "-q"}, dir,
                                  0.7, SIGTERM, &after);
  ::kill(writer, SIGKILL);
  ::waitpid(writer, nullptr, 0);
  EXPECT_EQ(code, 128 + SIGTERM);
  EXPECT_LT(after, 1.0);
  EXPECT_FALSE(fs::exists(dir / "out"));
}
