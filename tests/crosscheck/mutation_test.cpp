// A mutation harness over the readers of the files the programs take back or take from users: the
// cross-check's own JSON (the report's inputs, the suite's results), suite family files, experiments
// files and campaign files. Each seed is mutated — JSON structurally (a value replaced by one of
// another type or an extreme, a key or an element removed, a container emptied or extended), YAML
// byte-wise and token-wise — and handed to its reader and to what reads the reader's result (the
// report, the suite summary, the cases' scenarios). The only acceptable outcomes are success and
// io::InputError (exit 2 in the programs, one line naming the file and the field): any other
// exception fails the test and prints the mutant; a crash kills it.
//
// The mutant counts scale with SCOLEID_MUTANTS (default 1; the slow test Mutation.Million runs 50,
// over a million executions in all).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/cli_support.h"
#include "scoleid/crosscheck/campaign.h"
#include "scoleid/crosscheck/mismatch_suite.h"
#include "scoleid/crosscheck/report.h"
#include "scoleid/identify/door/experiments_door.h"
#include "scoleid/io/error.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace scoleid;
using scoleid::test::scratch;
using scoleid::test::slurp;
using scoleid::test::write_file;

namespace {

using Rng = std::mt19937_64;

long scaled(long base) {
  const char* s = std::getenv("SCOLEID_MUTANTS");
  const long k = s ? std::atol(s) : 1;
  return base * std::max(1L, k);
}

std::size_t pick(Rng& rng, std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); }

// A value unlike the one it replaces: another type, an extreme, an empty or odd container.
json odd_value(Rng& rng) {
  switch (pick(rng, 16)) {
    case 0:
      return nullptr;
    case 1:
      return true;
    case 2:
      return 0;
    case 3:
      return -1;
    case 4:
      return 1e308;
    case 5:
      return -1e308;
    case 6:
      return 4.9e-324;
    case 7:
      return std::numeric_limits<std::uint64_t>::max();
    case 8:
      return std::numeric_limits<std::int64_t>::min();
    case 9:
      return "";
    case 10:
      return std::string(100000, 'x');
    case 11:
      return json::array();
    case 12:
      return json::object();
    case 13:
      return json::array({nullptr, json::array()});
    case 14:
      return json{{"a", 1}};
    default:
      return 2.5;
  }
}

// Every node's pointer, the root included.
void collect(const json& j, const json::json_pointer& at, std::vector<json::json_pointer>& out) {
  out.push_back(at);
  if (j.is_object())
    for (auto it = j.begin(); it != j.end(); ++it) collect(it.value(), at / it.key(), out);
  else if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i) collect(j[i], at / i, out);
}

void mutate_json(json& doc, Rng& rng) {
  std::vector<json::json_pointer> nodes;
  collect(doc, json::json_pointer(), nodes);
  const json::json_pointer p = nodes[pick(rng, nodes.size())];
  json& v = doc.at(p);
  switch (pick(rng, 6)) {
    case 0:
      v = odd_value(rng);
      break;
    case 1: {  // removed from its parent
      if (p.empty()) break;
      json& parent = doc.at(p.parent_pointer());
      if (parent.is_object())
        parent.erase(p.back());
      else
        parent.erase(std::stoul(p.back()));
      break;
    }
    case 2:
      if (v.is_structured())
        v.clear();
      else
        v = odd_value(rng);
      break;
    case 3:  // extended
      if (v.is_array())
        v.push_back(v.empty() || pick(rng, 2) ? odd_value(rng) : v[pick(rng, v.size())]);
      else if (v.is_object())
        v["unexpected"] = odd_value(rng);
      else
        v = json::array({v, v});
      break;
    case 4:  // a number turned extreme or negative, a text made long or empty
      if (v.is_number())
        v = pick(rng, 2) ? -v.get<double>() : v.get<double>() * 1e300;
      else if (v.is_string())
        v = pick(rng, 2) ? std::string() : std::string(200000, 'y');
      else
        v = odd_value(rng);
      break;
    default:  // an element repeated many times
      if (v.is_array() && !v.empty())
        for (int k = 0; k < 50; ++k) v.push_back(v[pick(rng, v.size())]);
      else
        v = odd_value(rng);
  }
}

const char* const kYamlTokens[] = {":",        "- ",   "[",     "]",  "{",    "}",    ",",      "\t",
                                   "\n",       " ",    "'",     "\"", "&a ",  "*a",   "<<: *a", "!!binary ",
                                   "~",        "null", "1e308", "-1", ".nan", ".inf", "0",      "99999999999999999999",
                                   "\xff\xfe", "#",    "|\n  ", "? ", "...",  "---\n"};

std::string mutate_text(std::string s, Rng& rng) {
  const std::size_t n = s.size();
  if (n == 0) return kYamlTokens[pick(rng, std::size(kYamlTokens))];
  switch (pick(rng, 6)) {
    case 0:
      s[pick(rng, n)] = static_cast<char>(pick(rng, 256));
      break;
    case 1: {
      const std::size_t a = pick(rng, n);
      s.erase(a, 1 + pick(rng, std::min<std::size_t>(40, n - a)));
      break;
    }
    case 2:
      s.insert(pick(rng, n + 1), kYamlTokens[pick(rng, std::size(kYamlTokens))]);
      break;
    case 3:
      s.resize(pick(rng, n));
      break;
    case 4: {  // a line repeated (duplicate keys, duplicate list entries)
      const std::size_t a = s.rfind('\n', pick(rng, n));
      const std::size_t b0 = a == std::string::npos ? 0 : a + 1;
      const std::size_t b1 = s.find('\n', b0);
      const std::string line = s.substr(b0, b1 == std::string::npos ? std::string::npos : b1 - b0 + 1);
      s.insert(b0, line);
      break;
    }
    default: {  // a number replaced by an extreme
      const std::size_t a = s.find_first_of("0123456789", pick(rng, n));
      if (a == std::string::npos) break;
      const std::size_t b = s.find_first_not_of("0123456789.e-", a);
      s.replace(a, (b == std::string::npos ? n : b) - a, kYamlTokens[17 + pick(rng, 7)]);
    }
  }
  return s;
}

// Runs `attempt` on `mutants` mutants; fails with the first few that end in anything but success
// or io::InputError. Returns how many were refused.
template <class Attempt>
long expect_refused_or_read(const char* what, long mutants, Attempt attempt) {
  long refused = 0, wrong = 0;
  for (long k = 0; k < mutants; ++k) {
    std::string shown;
    try {
      attempt(k, shown);
    } catch (const io::InputError&) {
      ++refused;
    } catch (const std::exception& e) {
      if (++wrong <= 3) ADD_FAILURE() << what << " mutant " << k << ": " << e.what() << "\n" << shown.substr(0, 2000);
    }
  }
  std::printf("  %-28s %8ld mutants, %8ld refused with a line, %ld otherwise\n", what, mutants, refused, wrong);
  EXPECT_EQ(wrong, 0) << what;
  return refused;
}

json report_modes() {
  return json::parse(R"({"scenario": "s", "structure": "beam", "segments": [10, 20], "elements": [8, 16],
    "modes": [{"index": 1, "chain_hz": [1.0, 1.1], "fe_hz": [1.2, 1.21], "chain_extrapolated_hz": 1.15,
     "analytic_hz": 1.16, "extrapolated_vs_fe": -0.04, "chain_rate": 2.0, "fe_rate": 2.1, "mac": 0.999},
     {"index": 2, "chain_hz": [6.0, 6.3], "fe_hz": [6.4, 6.41], "chain_extrapolated_hz": 6.4,
     "analytic_hz": null, "extrapolated_vs_fe": 0.001, "chain_rate": 1.9, "fe_rate": null, "mac": 0.98}]})");
}
json report_trajectories() {
  return json::parse(R"({"scenario": "s", "segments": [10, 20], "elements": 8, "sensors": [
    {"name": "w", "kind": "displacement", "relative_rms": [0.01, 0.003], "rate": 1.9},
    {"name": "theta", "kind": "rotation", "relative_rms": [0.02, 0.005], "rate": 2.0}]})");
}
json report_identify() {
  return json::parse(R"({"scenario": "s", "data": "chain truth", "segments": [10, 20], "all_converged": true,
    "parameters": [{"name": "EI", "truth": 30, "relative_error": [0.01, 0.002], "std": [0.1, 0.1],
     "covered_by_2std": [true, true], "half_width": [0.5, 0.5], "covered_by_interval": [true, false],
     "extrapolated_relative_error": 0.0001, "observed_rate": 2.1, "fe_on_fe_relative_error": 1e-6},
     {"name": "rho_A", "truth": 2, "relative_error": [null, 0.002], "std": [null, 0.1],
     "covered_by_2std": [false, true], "extrapolated_relative_error": null, "observed_rate": null,
     "fe_on_fe_relative_error": 1e-6}]})");
}
json suite_result() {
  return json::parse(R"({"family": "f", "mismatch": "m", "size_unit": "%", "reason": "r",
    "expectations_met": false, "checks": [{"held": false, "what": "w", "measured": "x"}],
    "cases": [{"label": "a", "size": 1, "explains_data": true, "fit_ratio": 1.2, "seeds": [1, 2],
      "seed_statistics": [{"name": "EI"}], "parameters": [
      {"name": "EI", "truth": 30, "estimate": 31, "identifiable": true, "covered": true,
       "relative_error": 0.03, "relative_half_width": 0.1},
      {"name": "rho_A", "truth": 2, "estimate": null, "identifiable": false, "covered": false,
       "relative_error": null, "relative_half_width": null}]},
      {"label": "b", "size": 5, "explains_data": false, "parameters": [
      {"name": "EI", "truth": 30, "estimate": 40, "identifiable": true, "covered": false,
       "relative_error": 0.33, "relative_half_width": 0.01}]}]})");
}

}  // namespace

TEST(Mutation, TheReportsInputsAreReadOrRefusedWithALine) {
  Rng rng(20261203);
  const json seeds[3] = {report_modes(), report_trajectories(), report_identify()};
  crosscheck::ReportInputs in{seeds[0], seeds[1], seeds[2]};
  ASSERT_NO_THROW(crosscheck::check_report_inputs(in, "out"));  // the seeds are as the verbs write them
  ASSERT_EQ(crosscheck::summary_lines(in).size(), 4u);
  const long refused = expect_refused_or_read("report inputs", scaled(8000), [&](long, std::string& shown) {
    json docs[3] = {seeds[0], seeds[1], seeds[2]};
    const std::size_t which = pick(rng, 3);
    for (std::size_t m = 1 + pick(rng, 3); m > 0; --m) mutate_json(docs[which], rng);
    if (pick(rng, 8) == 0) docs[pick(rng, 3)] = nullptr;  // a file absent
    shown = docs[which].dump(-1, ' ', false, json::error_handler_t::replace);
    const crosscheck::ReportInputs mutant{docs[0], docs[1], docs[2]};
    crosscheck::check_report_inputs(mutant, "out");
    crosscheck::summary_lines(mutant);
    crosscheck::make_report(mutant, pick(rng, 2) == 0);
  });
  EXPECT_GT(refused, 0);  // the mutations reach the checks
}

TEST(Mutation, SuiteResultsAreReadOrRefusedWithALine) {
  Rng rng(77);
  const json seed = suite_result();
  ASSERT_NO_THROW(crosscheck::check_suite_result(seed, "results/f.json"));
  const long refused = expect_refused_or_read("suite results", scaled(8000), [&](long, std::string& shown) {
    json doc = seed;
    for (std::size_t m = 1 + pick(rng, 3); m > 0; --m) mutate_json(doc, rng);
    shown = doc.dump(-1, ' ', false, json::error_handler_t::replace);
    crosscheck::check_suite_result(doc, "results/f.json");
    const std::vector<json> families{doc, seed};
    crosscheck::suite_report(families, crosscheck::summarise_suite(families));
  });
  EXPECT_GT(refused, 0);
}

TEST(Mutation, SuiteFamilyFilesAreReadOrRefusedWithALine) {
  Rng rng(5);
  const fs::path d = scratch("mutation", "suite");
  std::vector<std::string> seeds;
  for (const auto& f : crosscheck::suite_files(std::string(SCOLEID_SOURCE_DIR) + "/crosscheck/mismatch"))
    seeds.push_back(slurp(f));
  ASSERT_FALSE(seeds.empty());
  const std::string path = (d / "family.yaml").string();
  const long refused = expect_refused_or_read("suite family files", scaled(400), [&](long, std::string& shown) {
    shown = seeds[pick(rng, seeds.size())];
    for (std::size_t m = 1 + pick(rng, 3); m > 0; --m) shown = mutate_text(shown, rng);
    write_file(path, shown);
    const crosscheck::SuiteFile f = crosscheck::load_suite_file(path);
    for (std::size_t k = 0; k < f.cases.size(); ++k) crosscheck::case_scenario(f, k);
  });
  EXPECT_GT(refused, 0);
  fs::remove_all(d);
}

TEST(Mutation, ExperimentsFilesAreReadOrRefusedWithALine) {
  Rng rng(11);
  const fs::path d = scratch("mutation", "experiments");
  const fs::path two = fs::path(SCOLEID_SOURCE_DIR) / "identify/examples/two-runs";
  for (const char* f : {"reflector-pulse.yaml", "shuttle-moment.yaml"}) fs::copy_file(two / f, d / f);
  const std::string seeds[] = {
      slurp(two / "experiments.yaml"),
      "experiments: e\ndescription: d\nthreads: 2\nruns:\n  - {name: a, scenario: reflector-pulse.yaml, data: a.csv}\n"
      "  - {name: b, scenario: shuttle-moment.yaml}\n"
      "modes: {file: m.uff, scenario: b, std: {frequency: 0.001, damping: 0.1, shape: 0.01}, stations: [10, 20]}\n"};
  const std::string path = (d / "experiments.yaml").string();
  const long refused = expect_refused_or_read("experiments files", scaled(4000), [&](long, std::string& shown) {
    shown = seeds[pick(rng, std::size(seeds))];
    for (std::size_t m = 1 + pick(rng, 3); m > 0; --m) shown = mutate_text(shown, rng);
    write_file(path, shown);
    identify::load_experiments(path);
  });
  EXPECT_GT(refused, 0);
  fs::remove_all(d);
}

TEST(Mutation, CampaignFilesAreReadOrRefusedWithALine) {
  Rng rng(13);
  const fs::path d = scratch("mutation", "campaign");
  std::vector<std::string> seeds;
  for (const auto& e : fs::directory_iterator(fs::path(SCOLEID_SOURCE_DIR) / "crosscheck/campaigns"))
    seeds.push_back(slurp(e.path()));
  seeds.push_back(
      "campaign: c\nscenarios: [paper-beam-2]\noverlay: {simulation: {duration: 2}}\n"
      "grid: {truth.segments: [10, 20], truth.overrides.beam.zeta: [0, 0.01]}\nnoise: {relative: 0.02, seeds: 3, seed: "
      "9}\n");
  const std::string path = (d / "campaign.yaml").string();
  const long refused = expect_refused_or_read("campaign files", scaled(400), [&](long, std::string& shown) {
    shown = seeds[pick(rng, seeds.size())];
    for (std::size_t m = 1 + pick(rng, 3); m > 0; --m) shown = mutate_text(shown, rng);
    write_file(path, shown);
    crosscheck::load_campaign(path);
  });
  EXPECT_GT(refused, 0);
  fs::remove_all(d);
}
