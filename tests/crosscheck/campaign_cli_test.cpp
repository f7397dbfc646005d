// `scole-crosscheck campaign`: bad input is one line and exit 2 with nothing written; a campaign
// killed in the middle of a case resumes without running a stored case again and ends with the
// report of an uninterrupted run, byte for byte. Built with SCOLEID_TEST_MPI (label mpi): the same
// campaign on 2 MPI ranks gives the serial report byte for byte, with both ranks working, and a
// rank killed mid-case resumes likewise.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "test_support.h"

namespace fs = std::filesystem;

namespace {
using scoleid::test::sh;
using scoleid::test::slurp;
fs::path scratch(const std::string& tag) { return scoleid::test::scratch("campaign-cli", tag); }
const std::string exe = SCOLE_CROSSCHECK_EXE;
// Two chain resolutions of the SCOLE paper case, 5 s records, 3 noise seeds: 2 truths, 8 cases.
const char* kCampaign =
    "campaign: small\ndescription: two chain resolutions, three seeds\nscenarios: [paper-scole-1]\n"
    "overlay: {simulation: {duration: 5}}\ngrid: {truth.segments: [10, 20]}\nnoise: {relative: 0.01, seeds: 3, seed: 7}\n";
const char* kReport[] = {"report.md", "cases.csv", "points.csv", "histogram.csv", "campaign.json"};

fs::path campaign_file(const fs::path& d) {
  std::ofstream(d / "small.yaml") << kCampaign;
  return d / "small.yaml";
}
std::map<std::string, fs::file_time_type> stored(const fs::path& out) {
  std::map<std::string, fs::file_time_type> m;
  for (const auto& e : fs::directory_iterator(out / "cases")) m[e.path().filename().string()] = e.last_write_time();
  return m;
}
nlohmann::json timing(const fs::path& out) {
  std::ifstream in(out / "timing.json");
  return nlohmann::json::parse(in);
}
// A killed run's stored cases are kept as they are and not run again; the resumed run completes
// the campaign with the reference run's report.
void expect_resumed(const fs::path& ref, const fs::path& out, const std::map<std::string, fs::file_time_type>& before) {
  for (const auto& [name, t] : before) EXPECT_EQ(fs::last_write_time(out / "cases" / name), t) << name << " was written again";
  const auto t = timing(out);
  EXPECT_EQ(t["stored_before"].get<std::size_t>(), before.size());
  EXPECT_EQ(t["ran"].get<std::size_t>() + before.size(), 8u);
  for (const auto& task : t["tasks"]) EXPECT_EQ(before.count(task["task"].get<std::string>() + ".json"), 0u) << task;
  for (const char* f : kReport) EXPECT_EQ(slurp(ref / f), slurp(out / f)) << f;
}
}  // namespace

#ifndef SCOLEID_TEST_MPI
TEST(CampaignCli, BadInputIsOneLineExitTwoNothingWritten) {
  const fs::path d = scratch("bad");
  std::ofstream(d / "bad.yaml") << "campaign: c\nscenarios: [paper-scole-1]\ngrid: {truth.segments: [10, -4]}\n";
  EXPECT_EQ(sh(exe + " campaign " + (d / "bad.yaml").string() + " -o " + (d / "out").string() + " 2> " + (d / "err").string()), 2);
  const std::string err = slurp(d / "err");
  EXPECT_NE(err.find("bad.yaml"), std::string::npos) << err;
  EXPECT_NE(err.find("segments"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_FALSE(fs::exists(d / "out"));
  EXPECT_EQ(sh(exe + " campaign " + (d / "missing.yaml").string() + " -o " + (d / "out").string() + " 2> /dev/null"), 2);
  EXPECT_FALSE(fs::exists(d / "out"));
  // A directory holding a file of the user's is refused, the file untouched.
  const fs::path f = campaign_file(d);
  fs::create_directories(d / "mine");
  std::ofstream(d / "mine" / "report.txt") << "mine";
  EXPECT_EQ(sh(exe + " campaign " + f.string() + " -q -o " + (d / "mine").string() + " 2> " + (d / "err").string()), 2);
  EXPECT_NE(slurp(d / "err").find("report.txt"), std::string::npos) << slurp(d / "err");
  EXPECT_FALSE(fs::exists(d / "mine" / "cases"));
  EXPECT_EQ(slurp(d / "mine" / "report.txt"), "mine");
  fs::remove_all(d);
}

TEST(CampaignCli, ADirectoryInUseByAnotherRunIsRefused) {
  const fs::path d = scratch("lock");
  const fs::path f = campaign_file(d);
  fs::create_directories(d / "out");
  const int fd = ::open((d / "out" / ".lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);  // another run holds it
  EXPECT_EQ(sh(exe + " campaign " + f.string() + " -q -o " + (d / "out").string() + " 2> " + (d / "err").string()), 2);
  EXPECT_NE(slurp(d / "err").find("another campaign run"), std::string::npos) << slurp(d / "err");
  ::close(fd);
  fs::remove_all(d);
}

TEST(CampaignCli, KilledSerialRunResumesWithoutRepeatingCases) {
  const fs::path d = scratch("serial");
  const fs::path f = campaign_file(d);
  ASSERT_EQ(sh(exe + " campaign " + f.string() + " -q -o " + (d / "ref").string() + " > /dev/null"), 0);
  for (const char* r : kReport) EXPECT_TRUE(fs::exists(d / "ref" / r)) << r;
  const auto j = nlohmann::json::parse(slurp(d / "ref" / "campaign.json"));
  EXPECT_EQ(j["cases"].get<int>(), 8);
  EXPECT_EQ(j["failed"].get<int>(), 0);
  // Killed (exit 137, as SIGKILL) during its fourth case: three cases stored, nothing of the fourth.
  EXPECT_EQ(sh(exe + " campaign " + f.string() + " -q --kill-after 3 -o " + (d / "out").string() + " > /dev/null"), 137);
  const auto before = stored(d / "out");
  EXPECT_EQ(before.size(), 3u);
  EXPECT_FALSE(fs::exists(d / "out" / "report.md"));
  ASSERT_EQ(sh(exe + " campaign " + f.string() + " -q -o " + (d / "out").string() + " > /dev/null"), 0);
  expect_resumed(d / "ref", d / "out", before);
  // A third run has nothing to do and writes the same report.
  ASSERT_EQ(sh(exe + " campaign " + f.string() + " -q -o " + (d / "out").string() + " > /dev/null"), 0);
  EXPECT_EQ(timing(d / "out")["ran"].get<int>(), 0);
  for (const char* r : kReport) EXPECT_EQ(slurp(d / "ref" / r), slurp(d / "out" / r)) << r;
  fs::remove_all(d);
}

#else
namespace {
// Open MPI refuses root without these; oversubscription lets 2 ranks run on any machine.
const std::string mpirun = std::string("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 ") + MPIEXEC + " --oversubscribe -n 2 ";
}  // namespace

TEST(CampaignMpi, TwoRanksWriteTheSerialReportAndShareTheWork) {
  const fs::path d = scratch("mpi");
  const fs::path f = campaign_file(d);
  ASSERT_EQ(sh(exe + " campaign " + f.string() + " -q -o " + (d / "serial").string() + " > /dev/null"), 0);
  ASSERT_EQ(sh(mpirun + exe + " campaign " + f.string() + " -q -o " + (d / "mpi").string() + " > /dev/null"), 0);
  for (const char* r : kReport) EXPECT_EQ(slurp(d / "serial" / r), slurp(d / "mpi" / r)) << r;
  const auto t = timing(d / "mpi");
  EXPECT_EQ(t["ranks"].get<int>(), 2);
  std::set<int> ranks;
  std::set<std::string> tasks;
  for (const auto& task : t["tasks"]) {
    ranks.insert(task["rank"].get<int>());
    EXPECT_TRUE(tasks.insert(task["task"].get<std::string>()).second) << task << " ran twice";
  }
  EXPECT_EQ(ranks, (std::set<int>{0, 1}));  // both ranks ran tasks
  EXPECT_EQ(t["ran"].get<int>(), 8);
  EXPECT_EQ(tasks.size(), 10u);  // 2 truths and 8 cases, each once
  fs::remove_all(d);
}

TEST(CampaignMpi, KilledRankResumesWithoutRepeatingCases) {
  const fs::path d = scratch("mpi-kill");
  const fs::path f = campaign_file(d);
  ASSERT_EQ(sh(exe + " campaign " + f.string() + " -q -o " + (d / "ref").string() + " > /dev/null"), 0);
  // Rank 1 dies during its third case; mpirun ends the job.
  EXPECT_NE(sh(mpirun + exe + " campaign " + f.string() + " -q --kill-after 2 -o " + (d / "out").string() + " > /dev/null 2>&1"), 0);
  const auto before = stored(d / "out");
  EXPECT_GE(before.size(), 2u);
  EXPECT_LT(before.size(), 8u);
  ASSERT_EQ(sh(mpirun + exe + " campaign " + f.string() + " -q -o " + (d / "out").string() + " > /dev/null"), 0);
  expect_resumed(d / "ref", d / "out", before);
  fs::remove_all(d);
}
#endif
