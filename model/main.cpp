// scole-truth: the Simbody truth generator (docs/theory.md §9, §10).
//   scole-truth --scenario NAME|FILE --out DIR   writes DIR/truth.csv and DIR/truth.json
//   scole-truth --list-scenarios
//   scole-truth                                  the default SCOLE scenario into ./run/
// Exit codes: 0 success, 1 run failed (the integration, or a plausibility guard: a proof mass
// beyond its stroke, a rotation beyond the small-rotation bound; docs/truth-guards.md), 2 bad usage
// or bad input, 130/143 interrupted; one line on stderr on failure, and then no output (truth.csv
// and truth.json appear together or not at all).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <string>

#include "scoleid/io/output_paths.h"
#include "scoleid/io/program.h"
#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/validation.h"
#include "scoleid/io/scenario.h"
#include "scoleid/model/truth_run.h"

namespace {
constexpr const char* kDefaultScenario = "paper-scole-1";
}

int main(int argc, char** argv) {
  using namespace scoleid;
  CLI::App app{"scole-truth: Simbody truth trajectories (SCOLE and the paper's beams)"};
  std::string scenario = kDefaultScenario, out = "run", integrator;
  int segments = 0;
  double accuracy = 0.0;
  bool list = false, quiet = false, visualize = false;
  app.add_option("-s,--scenario", scenario, "built-in scenario name or YAML file")->capture_default_str();
  app.add_option("-o,--out", out, "output directory (truth.csv, truth.json)")->capture_default_str();
  app.add_option("--segments", segments,
                 "override truth.segments (2.." + std::to_string(io::limits::kMaxSegments) + ")");
  app.add_option("--integrator", integrator,
                 "override truth.integrator: auto (default: gauss-legendre for unconstrained, lightly damped chains "
                 "such as SCOLE started at rest, as every truth run is; trapezoidal for such chains started deformed or "
                 "moving; cpodes when the top chain modes are overdamped; rk-merson for constrained chains), "
                 "gauss-legendre (fourth order, A-stable; on SCOLE about 3x faster than trapezoidal and 100x more "
                 "accurate), trapezoidal (second order, A-stable, energy-conserving), rk-merson, rk-feldberg, rk3, "
                 "cpodes, cpodes-bdf2, verlet, semi-explicit-euler2");
  app.add_option("--accuracy", accuracy,
                 "override truth.accuracy: local error per step (trapezoidal: on the fundamental mode, "
                 "step <= (12 accuracy)^(1/3) / omega_ref (omega_ref: the fundamental mode, or a higher mode the inputs excite weighed by its share of the record, docs/theory.md 9.5); the default 1e-9 keeps the energy drift below 1e-6 over 50 "
                 "periods; gauss-legendre: step <= (720 accuracy)^(1/5) / omega_ref)");
  app.add_flag("--list-scenarios", list, "list the built-in scenarios and exit");
  std::string print_name;
  app.add_option("--print-scenario", print_name,
                 "print built-in scenario NAME as YAML and exit (start a scenario file by editing it)");
  app.add_flag("-q,--quiet", quiet, "no progress or summary on stderr");
  app.add_flag("--visualize", visualize, "show the run in simbody-visualizer (needs a display)");
  app.footer(
      "Exit codes: 0 success; 1 the run failed (integration failure, or the motion left the identifier's linear "
      "range: a proof mass beyond scole.actuator_stroke, a rotation beyond " +
      io::format_value(model::kSmallRotationBound) + " rad without truth.large_motion); "
      "2 bad usage or bad input; 130/143 interrupted by SIGINT/SIGTERM. "
      "On any failure nothing is written: truth.csv and truth.json are staged beside --out and moved into place "
      "together at the end.");
  if (const auto code = io::parse_command_line(app, argc, argv, "scole-truth")) return *code;
  io::install_interrupt_handlers();
  return io::guarded_main("scole-truth", [&] {
    if (io::print_builtin_scenarios(print_name, list)) return 0;
    io::Scenario sc = io::load_scenario(scenario);
    // Command-line overrides go into the scenario and through the same checks as the file.
    if (app.count("--segments")) {
      if (segments < 2 || segments > io::limits::kMaxSegments)
        throw io::InputError("command line: --segments must be an integer in [2, " +
                             std::to_string(io::limits::kMaxSegments) + "], got " + std::to_string(segments));
      sc.truth.segments = segments;
    }
    if (app.count("--accuracy")) {
      if (!(accuracy >= 1e-14 && accuracy < 1))
        throw io::InputError("command line: --accuracy must be in [1e-14, 1), got " + io::format_value(accuracy));
      sc.truth.accuracy = accuracy;
    }
    if (!integrator.empty()) sc.truth.integrator = integrator;
    io::validate_scenario(sc);
    model::TruthOptions opt;
    opt.segments = segments;
    opt.integrator = integrator;
    opt.accuracy = accuracy;
    opt.progress = !quiet;
    opt.visualize = visualize;
    auto set = [](const char* v) { const char* x = std::getenv(v); return x && *x; };
    if (visualize && !set("DISPLAY") && !set("WAYLAND_DISPLAY"))
      throw io::InputError("command line: --visualize needs a display (DISPLAY is not set)");
    std::string why;
    if (!opt.IsValid(&why)) throw io::InputError("command line: " + why);
    io::check_inputs_outside("--out", out, {scenario});
    io::RunDirectory run_dir(out, model::output_files(), "scole-truth");
    const model::TruthResult res = model::run_truth(sc, opt);
    model::write_truth(res, run_dir);
    run_dir.commit();
    if (!quiet)
      std::fprintf(stderr, "scole-truth: %s: %s -> %s/truth.csv\n", sc.name.c_str(),
                   res.summary.BriefReport().c_str(), out.c_str());
    return 0;
  });
}
