// scole-frf-bench: the frequency-domain path against the time-domain path on one record, side by
// side in one run (docs/theory.md §6.10).
//
// The record: `--data FILE` (a shaker-frf record, e.g. scole-truth's truth.csv), else the built-in
// shaker-frf synthesised on the FE model (32 elements): 20 s at 2048 Hz, a force and two
// accelerometers in steady state under a periodic multisine. On it:
//   1. the FRF path end to end from the record in memory (FRFs at the lines, the fit, the
//      assessment): best of three;
//   2. the time-domain path on the same record (identification.domain: time, its initial state
//      estimated: the record starts in steady state, not at rest), once; `--no-time` skips it;
// then the estimates, their intervals and whether the two agree within them, and the time ratio.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "best_of.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/data_source.h"

using namespace scoleid::identify;

int main(int argc, char** argv) {
  std::string data;
  bool time_path = true;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--data") && i + 1 < argc) data = argv[++i];
    else if (!std::strcmp(argv[i], "--no-time")) time_path = false;
    else {
      std::fprintf(stderr, "usage: scole-frf-bench [--data truth.csv] [--no-time]\n");
      return 2;
    }
  }
  const scoleid::io::Scenario sc = scoleid::io::load_scenario("shaker-frf");
  scoleid::io::DataTable table;
  if (!data.empty()) {
    table = scoleid::io::read_data(data, {});
  } else {
    auto synth = sc;
    synth.identification.domain = scoleid::io::Domain::Time;
    synth.identification.data_elements = 32;
    const Measurements m = synthesize(synth, 32, synth.identification.rtol, 6e-5, true);
    table = measurement_table(synth, m);
  }
  std::printf("record: %zu samples x %zu columns (%s)\n", table.t.size(), table.columns.size(), data.empty() ? "FE-synthetic, 32 elements" : data.c_str());
  RunOptions ro;
  ro.verbose = false;
  RunResult fr;
  const double t_frf = bench::best_of(3, [&] {
    auto p = make_problem(sc, table, "record");
    fr = run_identification(*p, ro);
  });
  std::printf("FRF path:  %.3f s end to end, %s, %d iterations\n", t_frf, fr.converged() ? "converged" : "NOT converged", fr.summary.iterations_done);
  RunResult tr;
  double t_time = 0.0;
  if (time_path) {
    auto ts = sc;
    ts.identification.domain = scoleid::io::Domain::Time;
    ts.identification.initial_state = scoleid::io::InitialState::Estimate;
    const auto start = std::chrono::steady_clock::now();
    auto p = make_problem(ts, table, "record");
    tr = run_identification(*p, ro);
    t_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("time path: %.3f s end to end, %s, %d iterations\n", t_time, tr.converged() ? "converged" : "NOT converged", tr.summary.iterations_done);
  }
  std::printf("\n%-8s %14s %12s %14s %12s %10s\n", "", "FRF estimate", "interval", "time estimate", "interval", "agree");
  bool agree = true;
  for (std::size_t i = 0; i < fr.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const double hf = fr.interval.half_width[e];
    if (!time_path) {
      std::printf("%-8s %14.7g %12.3g\n", fr.names[i].c_str(), fr.estimate[e], hf);
      continue;
    }
    const double ht = tr.interval.half_width[e];
    const bool ok = std::abs(fr.estimate[e] - tr.estimate[e]) <= std::max(hf, ht);
    agree = agree && ok;
    std::printf("%-8s %14.7g %12.3g %14.7g %12.3g %10s\n", fr.names[i].c_str(), fr.estimate[e], hf, tr.estimate[e], ht, ok ? "yes" : "NO");
  }
  if (time_path) std::printf("\ntime path / FRF path: %.1fx; estimates %s within the intervals\n", t_time / t_frf, agree ? "agree" : "do NOT agree");
  return 0;
}
