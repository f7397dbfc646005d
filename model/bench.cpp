// scole-truth-bench: speed of the Simbody truth, measured side by side in one run.
//
// 1. Integrators on SCOLE (paper-scole-1 inputs), n segments (default 40), T simulated seconds
//    (default 20), output at 1 kHz: wall time, real-time factor, steps, and the trajectory error
//    against a tight reference (RK-Merson, accuracy 1e-10): max over sensors of
//    max_t |y - y_ref| / max_t |y_ref|.
// 0. First, the energy criterion of conservation_test.cpp (drift < 1e-6 over 50 periods) per
//    integrator and accuracy, which says at which accuracy each integrator qualifies.
// 2. Cost against n (10, 20, 40, 80) with the "auto" integrator at the default accuracy.
// --compare K: instead, paper-scole-1 as scole-truth runs it (n = 40, its 10 ms samples, its
//    accuracy), the trapezoidal rule and Gauss–Legendre alternating K times: the real-time factor
//    of each run and their ratio, and each method's trajectory error against RK-Merson at 1e-11.
// Runs that exceed the wall-time budget stop and are reported with the time they reached.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "scoleid/io/scenario.h"
#include "scoleid/model/linearisation.h"
#include "scoleid/model/sensors.h"
#include "scoleid/model/truth_run.h"

using namespace scoleid;
using namespace scoleid::model;

namespace {

struct Trajectory {
  std::vector<std::vector<double>> y;  // [sensor][sample]
  SimulateSummary summary;
};

Trajectory run(const io::Scenario& sc, int n, const std::string& integrator, double accuracy, double budget) {
  const auto st = prepare_structure(sc, n);
  const auto sensors = resolve_sensors(sc, *st);
  SimulateOptions o;
  o.integrator = integrator;
  o.accuracy = accuracy;
  o.final_time = sc.simulation.duration;
  o.sample_interval = sc.simulation.sample_interval;
  o.wall_limit = budget;
  for (const auto& in : sc.inputs)
    for (double b : in.signal.breakpoints()) o.breakpoints.push_back(b);
  Trajectory tr;
  tr.y.assign(sensors.size(), {});
  tr.summary = simulate(st->system(), st->system().getDefaultState(), o, [&](const SimTK::State& s) {
    for (std::size_t j = 0; j < sensors.size(); ++j) tr.y[j].push_back(read_sensor(st->matter(), s, sensors[j]));
  });
  return tr;
}

double trajectory_error(const Trajectory& a, const Trajectory& ref) {
  double e = 0.0;
  for (std::size_t j = 0; j < ref.y.size(); ++j) {
    double scale = 0.0, d = 0.0;
    for (double v : ref.y[j]) scale = std::max(scale, std::abs(v));
    for (std::size_t i = 0; i < a.y[j].size() && i < ref.y[j].size(); ++i) d = std::max(d, std::abs(a.y[j][i] - ref.y[j][i]));
    e = std::max(e, d / scale);
  }
  return e;
}

// The energy criterion of conservation_test.cpp: cantilever (L = 10, rho_A = 67, EI = 23000, tip
// mass 30 and rotary inertia 20), n = 10, undamped, unforced, deformed into a tip-load shape;
// max |E/E0 - 1| over 50 periods of its first mode. NaN if the budget ran out.
double energy_drift(const std::string& integrator, double accuracy, double budget, double* wall) {
  const io::Scenario sc = io::parse_scenario(
      "name: energy\nstructure: beam\nbeam: {length: 10, left: clamped, right: free, rho_A: 67, EI: 23000, "
      "zeta: 0, tip_mass: 30, tip_inertia: 20}\n", "energy criterion");
  const int n = 10;
  const auto st = prepare_structure(sc, n);
  SimTK::State s = st->system().getDefaultState();
  const auto& bodies = st->segment_bodies();
  for (const auto& j : st->joint_springs()) {
    const auto it = std::find(bodies.begin(), bodies.end(), j.body);
    const double shape = it == bodies.end() ? 0.0 : 1.0 - static_cast<double>(it - bodies.begin()) / n;
    st->matter().getMobilizedBody(j.body).setOneQ(s, j.which, 0.01 * shape);
  }
  const auto& sys = st->system();
  sys.realize(s, SimTK::Stage::Acceleration);
  const double E0 = sys.calcEnergy(s);
  const double T1 = 2 * SimTK::Pi / natural_modes(sys, sys.getDefaultState()).at(0).omega;
  SimulateOptions o;
  o.integrator = integrator;
  o.accuracy = accuracy;
  o.final_time = 50 * T1;
  o.sample_interval = T1 / 8;
  o.wall_limit = budget;
  double drift = 0.0;
  const auto sum = simulate(sys, s, o, [&](const SimTK::State& x) { drift = std::max(drift, std::abs(sys.calcEnergy(x) / E0 - 1)); });
  *wall = sum.wall_seconds;
  return sum.termination == SimulateSummary::Termination::Completed ? drift : NAN;
}

std::string drift_text(double d) {
  if (std::isnan(d)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%.2e", d);
  return b;
}

void row(const char* name, double acc, const Trajectory& t, double err) {
  const auto& s = t.summary;
  const bool done = s.termination == SimulateSummary::Termination::Completed;
  std::printf("%-22s %8.0e %9.2f %8.2f%s %9d %11d %10.2e\n", name, acc, s.wall_seconds, s.real_time_factor(),
              done ? " " : "*", s.steps_taken, s.realizations, done ? err : NAN);
}

// paper-scole-1 through run_truth (the scenario's samples, accuracy and segments): the two
// implicit fixed-step methods alternately, `times` times.
int compare_implicit_methods(int times) {
  io::Scenario sc = io::load_scenario("paper-scole-1");
  auto traj = [](const TruthResult& r) {
    Trajectory t;
    for (std::size_t j = r.table.columns.size() - r.table.names.size(); j < r.table.columns.size(); ++j)
      t.y.push_back(r.table.columns[j]);
    return t;
  };
  TruthOptions ref_opt;
  ref_opt.integrator = "rk-merson";
  ref_opt.accuracy = 1e-11;
  const Trajectory ref = traj(run_truth(sc, ref_opt));
  std::printf("paper-scole-1 as scole-truth runs it (n = %d, %g s, samples every %g s, accuracy %g)\n",
              sc.truth.segments, sc.simulation.duration, sc.simulation.sample_interval, sc.truth.accuracy);
  std::printf("%4s %14s %14s %8s %14s %14s\n", "run", "trapezoidal RT", "gauss-leg. RT", "ratio", "trap. traj err",
              "gauss traj err");
  for (int k = 1; k <= times; ++k) {
    TruthOptions t, g;
    t.integrator = "trapezoidal";
    g.integrator = "gauss-legendre";
    const TruthResult rt = run_truth(sc, t), rg = run_truth(sc, g);
    const double ft = rt.summary.real_time_factor(), fg = rg.summary.real_time_factor();
    std::printf("%4d %14.2f %14.2f %8.2f %14.2e %14.2e\n", k, ft, fg, fg / ft, trajectory_error(traj(rt), ref),
                trajectory_error(traj(rg), ref));
    std::fflush(stdout);
  }
  std::printf("(traj err: max over sensors of max_t |y - y_ref| / max_t |y_ref|, y_ref from RK-Merson at 1e-11; inputs included)\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"scole-truth-bench: integrators and cost of the Simbody truth"};
  double duration = 20.0, budget = 60.0, output = 0.001;
  int n = 40;
  bool quick = false;
  int compare = 0;
  app.add_option("--duration", duration, "simulated seconds")->capture_default_str();
  app.add_option("--segments", n, "segments of the integrator comparison")->capture_default_str();
  app.add_option("--budget", budget, "wall-time budget per run [s]")->capture_default_str();
  app.add_option("--output-interval", output, "sample interval [s]")->capture_default_str();
  app.add_flag("--quick", quick, "only the default integrator and the cost table");
  app.add_option("--compare", compare,
                 "only paper-scole-1 as scole-truth runs it: trapezoidal and gauss-legendre alternating this many times");
  CLI11_PARSE(app, argc, argv);
  try {
    if (compare > 0) return compare_implicit_methods(compare);
    io::Scenario sc = io::load_scenario("paper-scole-1");
    sc.simulation.duration = duration;
    sc.simulation.sample_interval = output;

    struct Trial { const char* integrator; double accuracy; };
    const std::vector<Trial> trials = {
        {"gauss-legendre", 1e-8}, {"gauss-legendre", 1e-9}, {"gauss-legendre", 1e-10},
        {"trapezoidal", 1e-8}, {"trapezoidal", 1e-9}, {"trapezoidal", 1e-10},
        {"rk-merson", 1e-6}, {"rk-merson", 1e-8},
        {"rk3", 1e-6}, {"rk3", 1e-8},
        {"verlet", 1e-6}, {"verlet", 1e-8},
        {"semi-explicit-euler2", 1e-5}, {"semi-explicit-euler2", 1e-6},
        {"cpodes", 1e-6}, {"cpodes", 1e-8},
        {"cpodes-bdf2", 1e-6}, {"cpodes-bdf2", 1e-7}, {"cpodes-bdf2", 1e-8}};
    if (!quick) {
      std::printf("Energy criterion: undamped cantilever chain n = 10, max |E/E0 - 1| over 50 periods (must be < 1e-6)\n");
      std::printf("%-22s %8s %12s %9s\n", "integrator", "accuracy", "drift", "wall [s]");
      for (const auto& t : trials) {
        double wall = 0.0;
        const double d = energy_drift(t.integrator, t.accuracy, budget, &wall);
        std::printf("%-22s %8.0e %12s %9.2f%s\n", t.integrator, t.accuracy, drift_text(d).c_str(), wall,
                    std::isnan(d) ? "*" : "");
        std::fflush(stdout);
      }
      std::printf("\n");
    }

    std::printf("SCOLE (paper-scole-1 inputs), n = %d, %g s simulated, output every %g s\n", n, duration, output);
    std::printf("%-22s %8s %9s %9s %9s %11s %10s\n", "integrator", "accuracy", "wall [s]", "RT factor", "steps",
                "realizations", "traj. err");
    Trajectory ref;
    if (!quick) {
      ref = run(sc, n, "rk-merson", 1e-10, 0.0);
      row("rk-merson (reference)", 1e-10, ref, 0.0);
      std::fflush(stdout);
      for (const auto& t : trials) {
        const Trajectory tr = run(sc, n, t.integrator, t.accuracy, budget);
        row(t.integrator, t.accuracy, tr, trajectory_error(tr, ref));
        std::fflush(stdout);
      }
      std::printf("(* = stopped at the %g s wall budget; RT factor over the time reached)\n\n", budget);
    }

    const double acc = sc.truth.accuracy;
    const std::vector<int> ms = {10, 20, 40, 80};
    std::vector<Trajectory> runs;
    for (int m : ms) runs.push_back(run(sc, m, "auto", acc, 0.0));
    std::printf("Cost against n: auto integrator (%s), accuracy %g (scenario default), %g s simulated\n",
                runs.front().summary.integrator.c_str(), acc, duration);
    std::printf("%5s %9s %9s %9s %11s %14s %12s\n", "n", "wall [s]", "RT factor", "steps", "realizations",
                "us/realization", "diff vs 80");
    for (std::size_t i = 0; i < ms.size(); ++i) {
      const auto& s = runs[i].summary;
      std::printf("%5d %9.2f %9.2f %9d %11d %14.1f %12.2e\n", ms[i], s.wall_seconds, s.real_time_factor(), s.steps_taken,
                  s.realizations, 1e6 * s.wall_seconds / std::max(1, s.realizations),
                  trajectory_error(runs[i], runs.back()));
    }
    std::printf("(diff vs 80: the lumping's own trajectory error, max over sensors of max_t |y_n - y_80| / max_t |y_80|)\n");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scole-truth-bench: %s\n", e.what());
    return 1;
  }
}
