// Every program and every long-running verb ends on SIGTERM: launched on a default-sized run and
// signalled 1.5 s in (inside its setup or its first solves), each exits 143 within a second and
// leaves nothing beside --out (no staging directory, no temporary file); every verb but the
// resumable campaign, and scole-identify once it has an iterate to keep (a complete run marked
// "interrupted"), leaves no --out either. scole-data reads a large DAQ export (120 MB) for as long.
// (scole-crosscheck report re-renders an earlier run in well under a second: nothing to signal.)
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "test_support.h"

namespace fs = std::filesystem;

namespace {

struct Outcome {
  int code = -1;
  double after = -1.0;  // seconds from the signal to the exit
};

Outcome run_and_terminate(const std::vector<std::string>& argv, const fs::path& dir, double delay) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) ::_exit(99);
    std::FILE* devnull = std::fopen("/dev/null", "w");
    if (devnull) {
      ::dup2(fileno(devnull), 1);
      ::dup2(fileno(devnull), 2);
    }
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execv(args[0], args.data());
    ::_exit(98);
  }
  ::usleep(static_cast<useconds_t>(delay * 1e6));
  Outcome o;
  ::kill(pid, SIGTERM);
  const auto t0 = std::chrono::steady_clock::now();
  int status = 0;
  ::waitpid(pid, &status, 0);
  o.after = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return o;
}

}  // namespace

TEST(Signals, EveryProgramAndVerbEndsWithinASecondOfSigtermLeavingNothingBesideOut) {
  const std::string truth = SCOLE_TRUTH_EXE, identify = SCOLE_IDENTIFY_EXE, xc = SCOLE_CROSSCHECK_EXE,
                    data = SCOLE_DATA_EXE;
  const std::string family = std::string(SCOLEID_SOURCE_DIR) + "/crosscheck/mismatch/01-chain-discretisation.yaml";
  struct Case {
    const char* name;
    std::vector<std::string> argv;
    bool keeps_out;  // a resumable campaign keeps the cases it stored
    double delay = 1.5;  // s before SIGTERM: mid-run
  };
  const std::vector<Case> cases = {
      {"scole-truth", {truth, "--scenario", "paper-scole-1", "--segments", "80", "--out", "out", "-q"}, false},
      {"scole-identify", {identify, "--scenario", "beam-ei8", "--out", "out", "-q"}, false},
      {"crosscheck modes", {xc, "modes", "--scenario", "paper-scole-1", "--segments", "160", "--out", "out"}, false},
      {"crosscheck trajectories", {xc, "trajectories", "--scenario", "paper-scole-1", "--out", "out"}, false},
      {"crosscheck identify", {xc, "identify", "--scenario", "paper-scole-1", "--out", "out"}, false},
      {"crosscheck all", {xc, "all", "--scenario", "paper-scole-1", "--out", "out"}, false},
      {"crosscheck suite", {xc, "suite", "--only", family, "--out", "out", "-q"}, false},
      {"crosscheck campaign", {xc, "campaign", "camp.yaml", "--out", "out"}, true},
      // A DAQ export of a force and two channels in g, 3·10⁶ samples each (160 MB: about a second
      // of parsing, so the signal comes at 0.25 s).
      {"scole-data info", {data, "info", "daq.csv"}, false, 0.25},
      {"scole-data convert", {data, "convert", "daq.csv", "--out", "out.csv", "-q"}, false, 0.25},
      {"scole-data frf", {data, "frf", "daq.csv", "--input", "F [N]", "--out", "out.uff", "-q"}, false, 0.25},
  };
  const auto inputs = [](const fs::path& d, bool daq) {
    std::ofstream(d / "camp.yaml") << "campaign: c\nscenarios: [paper-scole-1]\ngrid: {truth.segments: [80, 160]}\n";
    if (!daq) return;
    std::FILE* f = std::fopen((d / "daq.csv").c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fprintf(f, "# exported by a DAQ\ntime [s],F [N],acc1 [g],acc2 [g]\n");
    for (long k = 0; k < 3000000; ++k) {
      const double t = 1e-4 * static_cast<double>(k);
      std::fprintf(f, "%.6e,%.6e,%.6e,%.6e\n", t, std::sin(60.0 * t), 0.01 * std::sin(6.0 * t), 0.02 * std::cos(6.0 * t));
    }
    ASSERT_EQ(std::fclose(f), 0);
  };
  for (const auto& c : cases) {
    std::string tag = c.name;
    for (char& ch : tag)
      if (ch == ' ') ch = '-';
    const fs::path d = scoleid::test::scratch("xc-signal", tag);
    inputs(d, tag.rfind("scole-data", 0) == 0);
    const Outcome o = run_and_terminate(c.argv, d, c.delay);
    std::printf("  %-24s exit %d, %.3f s after SIGTERM\n", c.name, o.code, o.after);
    EXPECT_EQ(o.code, 128 + SIGTERM) << c.name;
    EXPECT_LT(o.after, 1.0) << c.name;
    for (const auto& e : fs::directory_iterator(d)) {
      const std::string n = e.path().filename().string();
      // scole-identify keeps the last iterate of a run interrupted while it iterates, as a
      // complete run marked "interrupted" (cli_test.cpp).
      bool kept_run = false;
      if (tag == "scole-identify" && n == "out") {
        std::ifstream in(e.path() / "identify.json");
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        kept_run = text.find("\"termination\": \"interrupted\"") != std::string::npos;
      }
      EXPECT_TRUE(n == "camp.yaml" || n == "daq.csv" || (c.keeps_out && n == "out") || kept_run) << c.name << " left " << n;
    }
    fs::remove_all(d);
  }
}
