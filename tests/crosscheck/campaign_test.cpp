// Campaigns (crosscheck/campaign*.h): the schedule hands every unfinished case out exactly once and
// never before its truth, costliest truth first, nothing stored before; the file's points are the
// grid's product with distinct fingerprints; bad files are one line naming the field; the report's
// seed statistics are the ones computed by hand.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "scoleid/crosscheck/campaign.h"
#include "scoleid/crosscheck/campaign_schedule.h"
#include "scoleid/crosscheck/scenario_overlay.h"
#include "scoleid/io/error.h"

namespace fs = std::filesystem;
using scoleid::crosscheck::CampaignSchedule;
using scoleid::crosscheck::CampaignTask;
using Kind = CampaignTask::Kind;
using Next = CampaignSchedule::Next;

namespace {
fs::path scratch(const std::string& tag) {
  const fs::path d = fs::temp_directory_path() / ("scoleid-campaign-" + tag + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}
void write(const fs::path& p, const std::string& s) { std::ofstream(p) << s; }
}  // namespace

TEST(CampaignSchedule, CostliestTruthFirstThenCasesInOrderWaitThenDone) {
  // Points 0, 1, 2 with truth costs 1, 5, 2; cases 0-1 on point 0, 2-3 on point 1, 4 on point 2.
  CampaignSchedule s({0, 0, 1, 1, 2}, {1, 5, 2}, {false, false, false}, std::vector<bool>(5, false));
  CampaignTask t;
  ASSERT_EQ(s.next(t), Next::Run);
  EXPECT_EQ(t.kind, Kind::Truth);
  EXPECT_EQ(t.index, 1u);
  ASSERT_EQ(s.next(t), Next::Run);
  EXPECT_EQ(t.index, 2u);
  ASSERT_EQ(s.next(t), Next::Run);
  EXPECT_EQ(t.index, 0u);
  EXPECT_EQ(s.next(t), Next::Wait);  // every truth runs elsewhere; no case is ready
  s.finished({Kind::Truth, 2});
  ASSERT_EQ(s.next(t), Next::Run);
  EXPECT_EQ(t.kind, Kind::Case);
  EXPECT_EQ(t.index, 4u);
  EXPECT_EQ(s.next(t), Next::Wait);
  s.finished({Kind::Truth, 0});
  ASSERT_EQ(s.next(t), Next::Run);
  EXPECT_EQ(t.index, 0u);
  ASSERT_EQ(s.next(t), Next::Run);
  EXPECT_EQ(t.index, 1u);
  s.finished({Kind::Truth, 1});
  ASSERT_EQ(s.next(t), Next::Run);
  EXPECT_EQ(t.index, 2u);
  ASSERT_EQ(s.next(t), Next::Run);
  EXPECT_EQ(t.index, 3u);
  EXPECT_EQ(s.next(t), Next::Done);  // all handed out
  EXPECT_EQ(s.cases_left(), 5u);     // none finished yet
}

TEST(CampaignSchedule, StoredCasesAndTruthsAreNeverHandedOutAgain) {
  // Point 0's cases are stored: its truth is not needed. Point 1's truth is stored, one case too.
  CampaignSchedule s({0, 0, 1, 1}, {1, 1}, {false, true}, {true, true, false, true});
  EXPECT_EQ(s.cases_done_before(), 3u);
  CampaignTask t;
  ASSERT_EQ(s.next(t), Next::Run);
  EXPECT_EQ(t.kind, Kind::Case);
  EXPECT_EQ(t.index, 2u);
  EXPECT_EQ(s.next(t), Next::Done);
}

TEST(CampaignSchedule, RanksOfRandomSpeedRunEveryCaseOnceAfterItsTruth) {
  // A discrete-event simulation: 3 ranks, random task durations spanning 100x.
  std::mt19937 rng(5);
  const std::size_t P = 7;
  std::vector<std::size_t> case_point;
  for (std::size_t p = 0; p < P; ++p)
    for (std::size_t k = 0; k < 1 + p % 4; ++k) case_point.push_back(p);
  std::vector<double> cost(P);
  for (auto& c : cost) c = std::uniform_real_distribution<double>(1, 100)(rng);
  std::vector<bool> case_done(case_point.size(), false);
  case_done[3] = true;
  CampaignSchedule s(case_point, cost, std::vector<bool>(P, false), case_done);
  struct Busy { double until; CampaignTask t; bool idle; };
  std::vector<Busy> ranks(3, Busy{0, {}, true});
  std::vector<int> runs(case_point.size(), 0);
  std::vector<double> truth_end(P, -1), case_start(case_point.size(), -1);
  double now = 0;
  for (int guard = 0; guard < 10000; ++guard) {
    bool all_done = true;
    for (auto& r : ranks) {
      if (!r.idle) continue;
      CampaignTask t;
      const auto n = s.next(t);
      if (n == Next::Run) {
        r = {now + std::uniform_real_distribution<double>(0.1, 10)(rng), t, false};
        if (t.kind == Kind::Case) {
          ++runs[t.index];
          case_start[t.index] = now;
        }
      }
      all_done = all_done && n == Next::Done;
    }
    std::size_t first = ranks.size();
    for (std::size_t i = 0; i < ranks.size(); ++i)
      if (!ranks[i].idle && (first == ranks.size() || ranks[i].until < ranks[first].until)) first = i;
    if (first == ranks.size()) {
      ASSERT_TRUE(all_done);
      break;
    }
    now = ranks[first].until;
    s.finished(ranks[first].t);
    if (ranks[first].t.kind == Kind::Truth) truth_end[ranks[first].t.index] = now;
    ranks[first].idle = true;
  }
  for (std::size_t k = 0; k < case_point.size(); ++k) {
    EXPECT_EQ(runs[k], k == 3 ? 0 : 1) << "case " << k;
    if (k != 3) {
      EXPECT_GE(case_start[k], truth_end[case_point[k]]) << "case " << k;
    }
  }
  EXPECT_EQ(s.cases_left(), 0u);
}

TEST(ScenarioOverlay, DottedPathBecomesNestedMap) {
  EXPECT_EQ(scoleid::crosscheck::path_overlay("truth.overrides.scole.zeta", "0.003"), "truth:\n  overrides:\n    scole:\n      zeta: 0.003");
}

TEST(CampaignFile, GridProductPointsCasesAndFingerprints) {
  const fs::path d = scratch("file");
  write(d / "c.yaml",
        "campaign: c\nscenarios: [paper-beam-2]\noverlay: {simulation: {duration: 2}}\n"
        "grid: {truth.segments: [10, 20, 40], truth.overrides.beam.zeta: [0, 0.01]}\nnoise: {relative: 0.02, seeds: 3, seed: 9}\n");
  const auto c = scoleid::crosscheck::load_campaign((d / "c.yaml").string());
  ASSERT_EQ(c.points.size(), 6u);
  ASSERT_EQ(c.cases.size(), 6u * 4u);
  // Last grid path fastest.
  EXPECT_EQ(c.points[0].scenario.truth.segments, 10);
  EXPECT_EQ(c.points[1].scenario.truth.segments, 10);
  EXPECT_EQ(c.points[2].scenario.truth.segments, 20);
  EXPECT_NE(c.points[1].label.find("truth.overrides.beam.zeta=0.01"), std::string::npos) << c.points[1].label;
  EXPECT_DOUBLE_EQ(c.points[3].scenario.simulation.duration, 2.0);
  EXPECT_EQ(c.cases[0].id, "p000-ref");
  EXPECT_EQ(c.cases[4].id, "p001-ref");
  EXPECT_EQ(c.cases[7].id, "p001-s0002");
  std::set<std::string> keys;
  for (const auto& k : c.cases) keys.insert(k.key);
  EXPECT_EQ(keys.size(), c.cases.size());  // every case its own fingerprint
  // The same file gives the same fingerprints; another noise level changes every noisy case's.
  const auto again = scoleid::crosscheck::load_campaign((d / "c.yaml").string());
  EXPECT_EQ(again.cases[7].key, c.cases[7].key);
  write(d / "c2.yaml",
        "campaign: c\nscenarios: [paper-beam-2]\noverlay: {simulation: {duration: 2}}\n"
        "grid: {truth.segments: [10, 20, 40], truth.overrides.beam.zeta: [0, 0.01]}\nnoise: {relative: 0.03, seeds: 3, seed: 9}\n");
  const auto other = scoleid::crosscheck::load_campaign((d / "c2.yaml").string());
  EXPECT_NE(other.cases[7].key, c.cases[7].key);
  EXPECT_EQ(other.points[1].key, c.points[1].key);  // the truths are still the same
  EXPECT_EQ(other.cases[4].key, c.cases[4].key);    // and so are the noise-free identifications
  EXPECT_NE(scoleid::crosscheck::case_noise_seed(c, c.cases[6]), scoleid::crosscheck::case_noise_seed(c, c.cases[7]));
  fs::remove_all(d);
}

TEST(CampaignFile, BadFieldsAreOneLineNamingTheField) {
  const fs::path d = scratch("bad");
  const std::string head = "campaign: c\nscenarios: [paper-beam-2]\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {head + "frobnicate: 1\n", "frobnicate"},
      {"scenarios: [paper-beam-2]\n", "campaign"},
      {"campaign: 'a b'\nscenarios: [paper-beam-2]\n", "campaign"},
      {"campaign: c\nscenarios: []\n", "scenarios"},
      {"campaign: c\nscenarios: [no-such-scenario]\n", "no-such-scenario"},
      {head + "grid: {truth.segments: []}\n", "grid.truth.segments"},
      {head + "grid: {'truth..segments': [1]}\n", "grid"},
      {head + "grid: {truth.segments: [0]}\n", "segments"},
      {head + "grid: {beam.EI: [-5]}\n", "EI"},
      {head + "noise: {relative: 0.01, seeds: 2.5}\n", "noise.seeds"},
      {head + "noise: {relative: 1.5, seeds: 3}\n", "noise.relative"},
      {head + "noise: {relative: 0.01, seeds: 3, colour: pink}\n", "noise.colour"},
      {head + "grid: {truth.segments: [10]\n", "malformed"},
      {"campaign: c\nscenarios: [paper-beam-2, paper-beam-2]\n", "scenarios[1]"},
      {head + "grid: {truth.segments: [10, 10.0]}\n", "grid.truth.segments[1]"},
      {head + "grid: {truth.segments: [~, 20]}\n", "grid.truth.segments[0]"},
      {head + "noise: {relative: 0.01, seeds: 3}\nnoise: {relative: 0.02, seeds: 3}\n", "noise"},
      {head + "grid: {truth.segments: [10, 20], truth.segments: [40]}\n", "grid.truth.segments"},
      {head + "noise: {relative: 0.01, seeds: 100000}\ngrid: {truth.segments: [10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 110]}\n",
       "noise.seeds"},
      {head + "overlay: {sensors: []}\n", "sensors"},
      {head + "overlay: {truth: {segments: 10, segments: 1000}}\n", "overlay.truth.segments"},
  };
  int k = 0;
  for (const auto& [text, needle] : cases) {
    const fs::path f = d / ("bad" + std::to_string(k++) + ".yaml");
    write(f, text);
    try {
      scoleid::crosscheck::load_campaign(f.string());
      ADD_FAILURE() << "accepted: " << text;
    } catch (const scoleid::io::InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(needle), std::string::npos) << m;
      EXPECT_NE(m.find(f.filename().string()), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  }
  EXPECT_THROW(scoleid::crosscheck::load_campaign((d / "missing.yaml").string()), scoleid::io::InputError);
  fs::remove_all(d);
}

TEST(CampaignReport, SeedStatisticsAreTheHandComputedOnes) {
  const fs::path d = scratch("report");
  write(d / "c.yaml", "campaign: c\nscenarios: [paper-beam-2]\nnoise: {relative: 0.01, seeds: 4}\n");
  const auto c = scoleid::crosscheck::load_campaign((d / "c.yaml").string());
  ASSERT_EQ(c.cases.size(), 5u);
  // Estimates 10 (ref), then 9, 11, 10, 12 with std 1, 1, 2, 2; truth 10.5 and half-widths 1.
  const double est[] = {10, 9, 11, 10, 12}, sd[] = {0.5, 1, 1, 2, 2};
  std::vector<nlohmann::json> res;
  for (int k = 0; k < 5; ++k) {
    const bool covered = std::abs(est[k] - 10.5) <= 1.0;
    res.push_back({{"converged", true}, {"explains_data", true},
                   {"parameters", {{{"name", "EI"}, {"truth", 10.5}, {"estimate", est[k]}, {"relative_error", est[k] / 10.5 - 1},
                                    {"std", sd[k]}, {"half_width", 1.0}, {"relative_half_width", 1.0 / 10.5},
                                    {"identifiable", true}, {"covered", covered}}}}});
  }
  const auto files = scoleid::crosscheck::campaign_report(c, res);
  const auto j = nlohmann::json::parse(files.at("campaign.json"));
  const auto& s = j["summary"][0];
  // Seeds 9, 11, 10, 12: mean 10.5, sample std sqrt(5/3); mean reported std 1.5.
  EXPECT_NEAR(s["scatter_over_std"].get<double>(), std::sqrt(5.0 / 3.0) / 1.5, 1e-12);
  // |est - ref| / std = 1, 1, 0, 1: all within 1.96; covered (|est - 10.5| <= 1): 11, 10 -> 0.5.
  EXPECT_DOUBLE_EQ(s["within_1.96_std"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(s["interval_coverage"].get<double>(), 0.5);
  // Bias of the mean from ref in std of the mean: 0.5 / (sqrt(5/3)/2).
  EXPECT_NEAR(s["noise_bias_std_of_mean"].get<double>(), 0.5 / (std::sqrt(5.0 / 3.0) / 2.0), 1e-12);
  // The histogram holds every seed once, and the normal's expectation sums to the seeds inside [-4, 4).
  std::istringstream h(files.at("histogram.csv"));
  std::string line;
  std::getline(h, line);
  long count = 0;
  double expected = 0;
  while (std::getline(h, line)) {
    std::vector<std::string> f;
    std::stringstream ls(line);
    for (std::string x; std::getline(ls, x, ',');) f.push_back(x);
    count += std::stol(f[3]);
    expected += std::stod(f[4]);
  }
  EXPECT_EQ(count, 4);
  EXPECT_NEAR(expected, 4.0 * (std::erf(4.0 / std::sqrt(2.0))), 1e-3);
  // A draw without a finite std is left out of the statistics and counted apart; one draw left
  // gives no scatter.
  res[3]["parameters"][0]["std"] = nullptr;
  auto j3 = nlohmann::json::parse(scoleid::crosscheck::campaign_report(c, res).at("campaign.json"))["summary"][0];
  EXPECT_EQ(j3["seeds"].get<int>(), 4);
  EXPECT_EQ(j3["seeds_with_std"].get<int>(), 3);
  EXPECT_TRUE(j3["scatter_over_std"].is_number());
  for (int k : {1, 2}) res[static_cast<std::size_t>(k)]["parameters"][0]["std"] = nullptr;
  j3 = nlohmann::json::parse(scoleid::crosscheck::campaign_report(c, res).at("campaign.json"))["summary"][0];
  EXPECT_EQ(j3["seeds_with_std"].get<int>(), 1);
  EXPECT_TRUE(j3["scatter_over_std"].is_null());
  EXPECT_TRUE(j3["noise_bias_std_of_mean"].is_null());
  for (int k : {1, 2, 3}) res[static_cast<std::size_t>(k)]["parameters"][0]["std"] = sd[k];
  // A failed case is listed, not counted.
  res[2] = {{"failed", "something broke"}};
  const auto f2 = scoleid::crosscheck::campaign_report(c, res);
  EXPECT_NE(f2.at("report.md").find("something broke"), std::string::npos);
  EXPECT_EQ(nlohmann::json::parse(f2.at("campaign.json"))["failed"].get<int>(), 1);
  fs::remove_all(d);
}
