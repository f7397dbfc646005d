// The report reads the verbs' own JSON: a file edited or cut short is refused with one line naming
// the file and the field (exit 2 in the program), never a crash — the cases that crashed it:
// modes.json with `segments: []` or `fe_hz: []`, trajectories.json with `segments: []` or
// `relative_rms: []`, identify.json `{}`.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "scoleid/crosscheck/mismatch_suite.h"
#include "scoleid/crosscheck/report.h"
#include "scoleid/io/error.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace scoleid;

namespace {

json modes() {
  return json::parse(R"({"scenario": "s", "segments": [10, 20], "modes": [
    {"index": 1, "chain_hz": [1.0, 1.1], "fe_hz": [1.2], "chain_extrapolated_hz": 1.15, "analytic_hz": null,
     "extrapolated_vs_fe": -0.04, "chain_rate": 2.0, "fe_rate": null, "mac": 0.999}]})");
}
json trajectories() {
  return json::parse(R"({"scenario": "s", "segments": [10, 20], "elements": 8, "sensors": [
    {"name": "w", "kind": "displacement", "relative_rms": [0.01, 0.003], "rate": 1.9}]})");
}
json identify() {
  return json::parse(R"({"scenario": "s", "data": "chain truth", "segments": [10, 20], "all_converged": true, "parameters": [
    {"name": "EI", "truth": 30, "relative_error": [0.01, 0.002], "std": [0.1, 0.1], "covered_by_2std": [true, true],
     "half_width": [0.5, 0.5], "covered_by_interval": [true, true], "extrapolated_relative_error": 0.0001,
     "observed_rate": 2.1, "fe_on_fe_relative_error": 1e-6}]})");
}

fs::path write_dir(const json& m, const json& t, const json& i) {
  const fs::path d = fs::temp_directory_path() / ("scoleid-report-shape-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  std::ofstream(d / "modes.json") << m.dump();
  std::ofstream(d / "trajectories.json") << t.dump();
  std::ofstream(d / "identify.json") << i.dump();
  return d;
}

void expect_refused(const json& m, const json& t, const json& i, const std::string& file, const std::string& field) {
  const fs::path d = write_dir(m, t, i);
  try {
    crosscheck::read_report_inputs(d.string());
    ADD_FAILURE() << "accepted a broken " << file << " (" << field << ")";
  } catch (const io::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(file), std::string::npos) << what;
    EXPECT_NE(what.find("'" + field + "'"), std::string::npos) << what;
  }
  fs::remove_all(d);
}

}  // namespace

TEST(ReportShape, TheVerbsOwnShapeIsReadAndReported) {
  const fs::path d = write_dir(modes(), trajectories(), identify());
  const auto in = crosscheck::read_report_inputs(d.string());
  const auto lines = crosscheck::summary_lines(in);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_NE(lines[0].find("n = 10..20"), std::string::npos) << lines[0];
  const auto rf = crosscheck::make_report(in, false);
  EXPECT_FALSE(rf.files.empty());
  fs::remove_all(d);
}

TEST(ReportShape, EmptiedOrMissingFieldsAreRefusedWithFileAndField) {
  json m = modes();
  m["segments"] = json::array();
  expect_refused(m, trajectories(), identify(), "modes.json", "segments");
  m = modes();
  m["modes"][0]["fe_hz"] = json::array();
  expect_refused(m, trajectories(), identify(), "modes.json", "modes[0].fe_hz");
  m = modes();
  m["modes"][0]["chain_hz"] = json::array({1.0});  // one level short
  expect_refused(m, trajectories(), identify(), "modes.json", "modes[0].chain_hz");
  json t = trajectories();
  t["segments"] = json::array();
  expect_refused(modes(), t, identify(), "trajectories.json", "segments");
  t = trajectories();
  t["sensors"][0]["relative_rms"] = json::array();
  expect_refused(modes(), t, identify(), "trajectories.json", "sensors[0].relative_rms");
  expect_refused(modes(), trajectories(), json::object(), "identify.json", "scenario");
  json i = identify();
  i["parameters"][0]["covered_by_2std"][1] = "yes";
  expect_refused(modes(), trajectories(), i, "identify.json", "parameters[0].covered_by_2std[1]");
  i = identify();
  i["segments"] = json::array({10, -20});
  expect_refused(modes(), trajectories(), i, "identify.json", "segments[1]");
  // Lists emptied: a summary over nothing would read "within 0 % of the truth".
  i = identify();
  i["parameters"] = json::array();
  expect_refused(modes(), trajectories(), i, "identify.json", "parameters");
  m = modes();
  m["modes"] = json::array();
  expect_refused(m, trajectories(), identify(), "modes.json", "modes");
  t = trajectories();
  t["sensors"] = json::array();
  expect_refused(modes(), t, identify(), "trajectories.json", "sensors");
}

TEST(ReportShape, SuiteResultsAreCheckedBeforeTheSummary) {
  const json family = json::parse(R"({"family": "f", "mismatch": "m", "size_unit": "%", "reason": "r",
    "expectations_met": true, "checks": [{"held": true, "what": "w", "measured": "x"}],
    "cases": [{"label": "a", "size": 1, "explains_data": true, "parameters": [
      {"name": "EI", "truth": 30, "estimate": null, "identifiable": true, "covered": false,
       "relative_error": null, "relative_half_width": 0.1}]}]})");
  EXPECT_NO_THROW(crosscheck::check_suite_result(family, "results/f.json"));
  // A diverged estimate (null) is summarised, not a crash.
  const auto s = crosscheck::summarise_suite({family});
  EXPECT_EQ(s.cases, 1);
  EXPECT_NO_THROW(crosscheck::suite_report({family}, s));
  auto refused = [](const json& j, const std::string& field) {
    try {
      crosscheck::check_suite_result(j, "results/f.json");
      ADD_FAILURE() << "accepted (" << field << ")";
    } catch (const io::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("'" + field + "'"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("results/f.json"), std::string::npos) << e.what();
    }
  };
  refused(json::object(), "family");
  json f = family;
  f["cases"][0]["parameters"][0].erase("covered");
  refused(f, "cases[0].parameters[0].covered");
  f = family;
  f["cases"][0]["explains_data"] = "yes";
  refused(f, "cases[0].explains_data");
  f = family;
  f["expectations_met"] = false;
  f.erase("checks");
  refused(f, "checks");
}
