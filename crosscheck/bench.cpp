// scole-crosscheck-bench: the cross-check's speed figures in one run, on this machine.
//   modes     SCOLE (paper-scole-1), chain n = 80, 160, 320 against FE N = 40, 80, 160 (target < 10 s)
//   identify  paper-scole-1: truths at 40, 80, 160 segments, three identifications and the
//             FE-on-FE one (target < 60 s)
// Beside them, one 40-segment truth run of the same scenario, so the table also gives ratios,
// which travel between machines better than seconds.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <unistd.h>

#include "scoleid/crosscheck/identify_study.h"
#include "scoleid/crosscheck/modes.h"
#include "scoleid/io/scenario.h"
#include "scoleid/model/truth_run.h"

using namespace scoleid;
namespace fs = std::filesystem;

namespace {
template <class F>
double seconds(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

int main() {
  const io::Scenario sc = io::load_scenario("paper-scole-1");
  const fs::path dir = fs::temp_directory_path() / ("scoleid-xc-bench-" + std::to_string(::getpid()));
  const double truth = seconds([&] { model::run_truth(sc); });
  crosscheck::ModesOptions mo;
  mo.segments = 80;
  mo.elements = 40;
  const double modes = seconds([&] { crosscheck::compare_modes(sc, mo); });
  crosscheck::IdentifyStudyOptions io_;
  double ident = seconds([&] { crosscheck::identify_study(sc, io_, dir.string()); });
  fs::remove_all(dir);
  std::printf("%-44s %9s %9s %14s\n", "case (paper-scole-1)", "seconds", "target", "x one truth");
  std::printf("%-44s %9.2f %9s %14.2f\n", "one truth, 40 segments", truth, "-", 1.0);
  std::printf("%-44s %9.2f %9s %14.2f\n", "modes, n = 80..320 vs N = 40..160", modes, "< 10", modes / truth);
  std::printf("%-44s %9.2f %9s %14.2f\n", "identify, truths 40/80/160 + 4 identifications", ident, "< 60", ident / truth);
  return (modes < 10.0 && ident < 60.0) ? 0 : 1;
}
