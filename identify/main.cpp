// scole-identify: identify distributed parameters of a beam from measured or synthesised
// responses with the finite-element costate method. See README.md.
#include <algorithm>
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <mutex>
#include <thread>
#include <filesystem>
#include <iostream>
#include <optional>

#include "scoleid/io/program.h"
#include "scoleid/identify.h"
#include "scoleid/identify/door/experiments_door.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/io/error.h"
#include "scoleid/io/mat_file.h"
#include "scoleid/io/output_paths.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/validation.h"

using namespace scoleid;
using Eigen::VectorXd;

namespace {

// --max-wall-time: after `seconds` (0: never) the run is asked to stop as at a signal, SIGALRM
// standing for the limit (io::request_interrupt; the run keeps its last iterate, RunOptions).
class WallClock {
public:
  explicit WallClock(double seconds) {
    if (seconds > 0)
      thread_ = std::thread([this, seconds] {
        std::unique_lock<std::mutex> lock(m_);
        if (!cv_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return done_; })) io::request_interrupt(SIGALRM);
      });
  }
  void stop() {
    {
      std::lock_guard<std::mutex> lock(m_);
      done_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
  }
  ~WallClock() { stop(); }

private:
  std::mutex m_;
  std::condition_variable cv_;
  bool done_ = false;
  std::thread thread_;
};

// scole-identify --experiments FILE: the joint identification (identify/run/experiments.h).
int run_experiments_command(const std::string& file, std::string out, std::optional<io::Method> method, int threads,
                            int max_iterations, bool compute_std, bool verbose) {
  const identify::ExperimentsSpec spec = identify::load_experiments(file);
  if (out.empty()) out = "run/" + spec.name;
  {
    std::vector<std::string> inputs{file};
    for (const auto& r : spec.runs) {
      inputs.push_back(r.scenario);
      if (r.data) inputs.push_back(*r.data);
    }
    if (spec.modes_file) inputs.push_back(*spec.modes_file);
    io::check_inputs_outside("--out", out, inputs);
  }
  io::RunDirectory run_dir(out, identify::experiments_output_files(spec), "scole-identify");
  auto ep = identify::make_experiments(spec);
  identify::ExperimentsOptions eo;
  eo.method = method;
  eo.compute_std = compute_std;
  eo.verbose = verbose;
  if (threads >= 0) eo.threads = threads;
  if (max_iterations >= 0) eo.max_iterations = max_iterations;
  for (std::size_t i = 0; i < ep->runs.size(); ++i)
    std::fprintf(stderr, "scole-identify: run %s: %s, %d elements, data: %s\n", spec.runs[i].name.c_str(),
                 ep->runs[i]->scenario.name.c_str(), ep->runs[i]->structure->elements(), ep->runs[i]->data_source.c_str());
  if (ep->modes)
    std::fprintf(stderr, "scole-identify: modes: %zu measured modes from %s, model %s\n", ep->modes->modes.size(),
                 spec.modes_file->c_str(), ep->modes_scenario->name.c_str());
  const identify::ExperimentsResult r = identify::run_experiments(*ep, eo);
  identify::write_experiments_outputs(run_dir, *ep, r);
  run_dir.commit();
  // The joint estimate, its std, and each experiment's std alone at the estimate.
  std::printf("\n%-10s %14s %14s %12s %12s", "parameter", "estimate", "truth", "rel.error", "joint std");
  for (const auto& e : r.experiments) std::printf(" %14s", ("std " + e.name).substr(0, 14).c_str());
  std::printf("\n");
  auto sd = [](const identify::Identifiability& id, std::size_t i) {
    char buf[32];
    if (id.identifiable.empty()) return std::string("-");
    if (!id.identifiable[i]) return std::string("NOT IDENT.");
    std::snprintf(buf, sizeof buf, "%.3e", id.std[static_cast<Eigen::Index>(i)]);
    return std::string(buf);
  };
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const auto it = r.truth.find(r.names[i]);
    if (it != r.truth.end())
      std::printf("%-10s %14.7g %14.7g %12.3e %12s", r.names[i].c_str(), r.estimate[e], it->second,
                  r.estimate[e] / it->second - 1.0, sd(r.ident, i).c_str());
    else
      std::printf("%-10s %14.7g %14s %12s %12s", r.names[i].c_str(), r.estimate[e], "-", "-", sd(r.ident, i).c_str());
    for (const auto& x : r.experiments) std::printf(" %14s", sd(x.alone, i).c_str());
    std::printf("\n");
  }
  if (r.interval.half_width.size() == r.estimate.size()) {
    std::printf("\n%-10s %14s %14s   (%s)\n", "parameter", "± interval", "identifiable", r.interval.note.c_str());
    for (std::size_t i = 0; i < r.names.size(); ++i) {
      const double w = r.interval.half_width[static_cast<Eigen::Index>(i)];
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.4g", w);
      std::printf("%-10s %14s %14s\n", r.names[i].c_str(), std::isfinite(w) ? buf : "-",
                  r.ident.identifiable[i] ? "yes" : ("no: " + r.ident.reason[i]).c_str());
    }
  }
  std::printf("\n%-12s %-6s %10s %12s  %s\n", "experiment", "kind", "share", "data values", "fit");
  for (const auto& x : r.experiments)
    std::printf("%-12s %-6s %10.4f %12ld  %s\n", x.name.c_str(), x.kind.c_str(), x.share, x.data_values, x.fit_message.c_str());
  std::printf("\n%s; %d thread%s; %.3f s\nwrote %s/identify.json\n", r.summary.BriefReport().c_str(), r.threads,
              r.threads == 1 ? "" : "s", r.wall_seconds, out.c_str());
  if (!r.summary.converged()) {
    std::fprintf(stderr, "scole-identify: did not converge (%s%s%s); outputs written with \"converged\": false\n",
                 identify::to_string(r.summary.termination), r.summary.message.empty() ? "" : ": ",
                 io::one_line(r.summary.message).c_str());
    return 1;
  }
  if (!r.converged()) {
    std::fprintf(stderr,
                 "scole-identify: stopped at a point that does not explain the data of every experiment; outputs written "
                 "with \"converged\": false\n");
    return 1;
  }
  return 0;
}

// The problem on stderr: scenario, model, mesh, parameters, the data and how its columns are used.
void print_problem(const identify::Problem& problem, bool from_file) {
  const auto& sc = problem.scenario;
  std::fprintf(stderr, "scole-identify: %s, %s model, %d elements, %d parameters, data: %s\n", sc.name.c_str(),
               io::to_string(sc.identification.model), problem.structure->elements(), problem.params->size(),
               problem.data_source.c_str());
  if (problem.frf) std::fprintf(stderr, "scole-identify: frequency domain: %s\n", problem.frf_note.c_str());
  if (!from_file) return;
  auto list = [](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s.empty() ? std::string("none") : s;
  };
  const auto& c = problem.columns;
  std::fprintf(stderr, "scole-identify: data columns: sensors %s; inputs from data %s; inputs from the scenario %s; unused %s\n",
               list(c.sensors).c_str(), list(c.inputs_from_data).c_str(), list(c.inputs_from_scenario).c_str(),
               list(c.unused).c_str());
  if (c.window.size() == 2)
    std::fprintf(stderr, "scole-identify: fit window (data.window): the samples from %s to %s s, the model starting at the first\n",
                 io::format_value(c.window[0]).c_str(), io::format_value(c.window[1]).c_str());
  for (const auto& x : c.sources) {
    if (x.column != x.name || !x.from_unit.empty())
      std::fprintf(stderr, "scole-identify: %s <- column '%s'%s\n", x.name.c_str(), x.column.c_str(),
                   x.from_unit.empty() ? ""
                                       : (" [" + x.from_unit + ", " + x.unit_stated_by + "] x " + io::format_value(x.scale) +
                                          " -> [" + x.to_unit + "]").c_str());
    if (x.conditioned)
      std::fprintf(stderr, "scole-identify: %s conditioned: offset %s removed, times %s%s\n", x.name.c_str(),
                   io::format_value(x.offset_removed).c_str(), io::format_value(x.factor).c_str(),
                   x.trend_removed.second != 0.0 || x.trend_removed.first != 0.0
                       ? (", trend " + io::format_value(x.trend_removed.first) + " + " + io::format_value(x.trend_removed.second) +
                          " (t - mid) removed")
                             .c_str()
                       : "");
  }
  for (const auto& st : c.stepped_inputs) {
    if (st.windowed)
      std::fprintf(stderr,
                   "scole-identify: input '%s': force window %g .. %g s (an impact; the column is zero outside it, where it "
                   "read only its noise; conditioning: {window: none} keeps it)\n",
                   st.name.c_str(), st.window_from, st.window_to);
    if (st.hits.size() > 1) {
      std::string hits;
      for (const auto& [at, rel] : st.hits) hits += (hits.empty() ? "" : ", ") + io::format_value(at) + " s (" + io::format_value(std::round(100 * rel)) + " %)";
      std::fprintf(stderr, "scole-identify: warning: input '%s': a double hit: %zu hits at %s; the model is driven by all of them\n",
                   st.name.c_str(), st.hits.size(), hits.c_str());
    }
    if (st.cubic) {
      std::fprintf(stderr,
                   "scole-identify: warning: input '%s' from the data jumps by %g within one sample (to t = %g) and is read "
                   "cubically between samples (interpolation: cubic), which overshoots at each jump; interpolation: linear "
                   "keeps each jump within its sample\n",
                   st.name.c_str(), st.jump, st.at);
      continue;
    }
    if (st.pulse_samples > 0) {  // an impact: its samples are what was measured; no advice to replace them
      std::fprintf(stderr,
                   "scole-identify: note: input '%s' from the data is a pulse over %d samples (largest change %g within one "
                   "sample, at t = %g): piecewise linear between samples, which keeps its impulse; its content near the "
                   "sampling rate (%g Hz) is not resolved\n",
                   st.name.c_str(), st.pulse_samples, st.jump, st.at, 1.0 / st.sample);
      continue;
    }
    std::fprintf(stderr,
                 "scole-identify: warning: input '%s' from the data jumps by %g within one sample (to t = %g): "
                 "piecewise linear between samples, each jump moves by up to half a sample (%g s)%s\n",
                 st.name.c_str(), st.jump, st.at, 0.5 * st.sample,
                 st.scenario_signal ? "; the scenario gives its signal: signal_from: scenario drives the model with it" : "");
  }
  for (const auto& w : problem.warnings) std::fprintf(stderr, "scole-identify: warning: %s\n", w.c_str());
  if (!problem.band_note.empty())
    std::fprintf(stderr, "scole-identify: band %s (identification.band: [f_lo, f_hi] states one, none fits the whole record)\n", problem.band_note.c_str());
}

// --export-model FILE: a .json or .mat file, no input of the run and outside --out, in a
// writable directory (checked before any work; io/output_paths.h).
void check_export_path(const std::string& path, const std::string& scenario, const std::string& data, const std::string& out) {
  if (path.empty()) return;
  const std::filesystem::path p(path);
  if (p.extension() != ".json" && p.extension() != ".mat")
    throw io::InputError("command line: --export-model must name a .json or .mat file, got '" + path + "'");
  if (p.extension() == ".mat" && !io::mat_files_supported())
    throw io::InputError("command line: --export-model '" + path + "': this build writes no .mat files (libmatio was not found); use .json");
  // A data file's metadata (truth.json beside truth.csv) is read too.
  const std::string meta = data.empty() ? std::string() : std::filesystem::path(data).replace_extension(".json").string();
  io::check_output_file("--export-model", path, {scenario, data, meta}, out);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "scole-identify: estimate a structure's distributed parameters (EI, rho_A, damping, EI(x)) from\n"
      "response data with a finite-element costate (adjoint) method.\n\n"
      "Without --data the scenario synthesises its own measurements on a mesh at least twice as fine as\n"
      "the identifier's, so the identifier never fits its own discretisation. Writes DIR/identify.json\n"
      "(estimates, truth, std, iteration history, counts, timings, settings) and DIR/fit.csv\n"
      "(measured, predicted, residual per sensor), and prints the iteration table. With\n"
      "identification.domain: frequency the fit compares frequency responses (made from the record, or read\n"
      "from a UFF file of FRFs given as --data) and fit.csv holds them per line (docs/theory.md 6.10).\n\n"
      "Exit codes: 0 converged; 1 the run failed, did not converge, or stopped at a point that does not explain\n"
      "the data (the fit test: residual beyond noise, discretisation and identification.model_error; its outputs\n"
      "are written, marked \"converged\": false; also a run stopped at --max-wall-time); 2 bad usage or bad input\n"
      "(nothing written); 130/143 interrupted by SIGINT/SIGTERM: during the optimiser or the assessment the last\n"
      "iterate reached is written, marked \"interrupted\" and not converged, before the first iterate nothing. The\n"
      "outputs of a run appear together or not at all: they are written beside --out and moved into place as one\n"
      "directory at the end.\n\n"
      "With --experiments FILE, several runs (each its own scenario: inputs, sensors, data; in the time domain,\n"
      "or as FRFs when the scenario says identification.domain: frequency) and/or measured modes (frequencies,\n"
      "damping ratios, shapes; CSV) are fitted with one parameter vector, the runs solved\n"
      "concurrently (README \"Several experiments and modal data\"). Writes identify.json (joint estimate, joint\n"
      "and per-experiment std, misfit share and residual RMS per experiment), fit-<run>.csv/.gp/.png per run and\n"
      "modes-fit.csv (measured against matched model modes)."};
  std::string scenario = "paper-beam-1";
  std::string data, out, method, export_model;
  int max_iterations = -1;
  bool list = false, no_std = false, quiet = false;
  app.add_option("-s,--scenario", scenario, "built-in scenario name or YAML file")->capture_default_str();
  app.add_option("-d,--data", data, "measured data: CSV (header t,<columns>; sensors and inputs matched by name), UFF, LVM, TDMS, MAT; with identification.domain: frequency also a UFF file of FRFs (function type 4)");
  app.add_option("-o,--out", out, "output directory (default: run/<scenario name>)");
  app.add_option("-m,--method", method, "optimiser: " + io::names_joined<io::Method>(" | ") + " (default: the scenario's)")
      ->check(CLI::IsMember(io::names<io::Method>()));
  app.add_option("--max-iterations", max_iterations, "override identification.max_iterations (>= 0)")
      ->check(CLI::Range(0, 100000));
  app.add_flag("--list-scenarios", list, "list the built-in scenarios and exit");
  std::string print_name;
  app.add_option("--print-scenario", print_name,
                 "print built-in scenario NAME as YAML and exit (start a scenario file by editing it)");
  app.add_flag("--no-std", no_std,
               "skip the Fisher-information standard deviations and with them the identifiability flags "
               "(identify.json then says \"identifiable\": null, not assessed)");
  app.add_flag("-q,--quiet", quiet, "do not print the iteration table");
  double max_wall_time = 0.0;
  app.add_option("--max-wall-time", max_wall_time,
                 "stop after SECONDS of wall time, keeping the last iterate reached as a complete run marked \"interrupted\" "
                 "(exit 1; nothing written if there is no iterate yet)")
      ->check(CLI::Range(1e-3, 1e9));
  auto* export_opt = app.add_option("--export-model", export_model,
                 "write the identified linear model to FILE.json or FILE.mat (MATLAB): state space A, B, C, D over the scenario's inputs and "
                 "sensors, and the modal model (frequencies, damping ratios, shapes at sensors and inputs)");
  std::string experiments;
  int threads = -1;
  auto* ex_opt = app.add_option("-e,--experiments", experiments,
                                "experiments file (YAML: runs [{name, scenario, data}], modes {file, scenario}, threads)");
  app.add_option("--threads", threads, "with --experiments: concurrent experiment solves (0 = the machine's threads)")
      ->check(CLI::Range(0, 1024))
      ->needs(ex_opt);
  ex_opt->excludes(app.get_option("--scenario"));
  ex_opt->excludes(app.get_option("--data"));
  ex_opt->excludes(export_opt);
  if (const auto code = io::parse_command_line(app, argc, argv, "scole-identify")) return *code;
  io::install_interrupt_handlers();
  WallClock wall_clock(max_wall_time);
  return io::guarded_main("scole-identify", [&] {
    // A path option given empty is a typo, not a request for the default.
    for (const char* name : {"--data", "--out", "--experiments", "--scenario", "--print-scenario", "--export-model"})
      if (app.count(name) > 0 && app.get_option(name)->as<std::string>().empty())
        throw io::InputError(std::string("command line: ") + name + " is empty (give a value, or leave the option out)");
    if (io::print_builtin_scenarios(print_name, list)) return 0;
    const std::optional<io::Method> method_given = method.empty() ? std::nullopt : io::parse<io::Method>(method);
    if (!experiments.empty())
      return run_experiments_command(experiments, out, method_given, threads, max_iterations, !no_std, !quiet);
    io::Scenario sc = io::load_scenario(scenario);
    IdentifyOptions options;
    options.method = method_given;
    options.compute_std = !no_std;
    options.verbose = !quiet;
    options.keep_interrupted = true;  // a run stopped by a signal or the wall-time limit keeps its last iterate
    if (max_iterations >= 0) {
      options.max_iterations = max_iterations;
      sc.identification.max_iterations = max_iterations;
    }
    io::validate_scenario(sc);  // the overrides pass the same checks as the file
    if (out.empty()) out = "run/" + sc.name;
    // The output directory is checked (and its staging area made) before any work.
    io::check_inputs_outside("--out", out,
                             {scenario, data, data.empty() ? std::string() : std::filesystem::path(data).replace_extension(".json").string()});
    io::RunDirectory run_dir(out, Identification::output_files(), "scole-identify");
    check_export_path(export_model, scenario, data, out);
    // The exported model is written beside its place during the run and put there after the
    // outputs: a run that fails or is interrupted leaves neither.
    std::optional<io::StagedFile> staged_model;
    if (!export_model.empty()) staged_model.emplace(export_model, "command line: --export-model");
    const auto problem = prepare(sc, data.empty() ? DataSource::synthetic() : DataSource::file(data), options.verbose);
    // (Checked again by the run; here so that the refusal is the only line on stderr.)
    if (const auto& w = sc.identification.steepest_weights; !w.empty() && static_cast<int>(w.size()) != problem->params->size())
      io::fail_field(sc.source, "identification.steepest_weights",
                     "must hold one weight per estimated parameter (" + std::to_string(problem->params->size()) + ")",
                     std::to_string(w.size()) + " values");
    print_problem(*problem, !data.empty());
    const Identification id = identify_parameters(problem, options);
    const int interrupted = id.result().interrupted_by;
    wall_clock.stop();
    if (!interrupted && io::interrupt_signal() == SIGALRM) io::clear_interrupt();  // the limit came as the run ended
    id.write(run_dir);
    if (staged_model && !interrupted) id.export_model(staged_model->path());  // an interrupted run is no model to export
    run_dir.commit();
    if (staged_model && !interrupted) staged_model->commit();
    std::printf("\n%s", id.FullReport().c_str());
    if (id.problem().frf)
      std::printf("wrote %s/identify.json, fit.csv (FRFs: measured and model per line), fit.gp (and fit.png with gnuplot)\n", out.c_str());
    else
      std::printf("wrote %s/identify.json, fit.csv, fit.gp, spectrum.csv, spectrum.gp%s (and fit.png, spectrum.png%s with gnuplot)\n", out.c_str(),
                  id.result().start_check.frf.empty() ? "" : ", start_frf.csv, start_frf.gp", id.result().start_check.frf.empty() ? "" : ", start_frf.png");
    for (const auto& w : id.warnings()) std::fprintf(stderr, "scole-identify: warning: %s\n", w.c_str());
    if (interrupted) {
      std::fprintf(stderr, "scole-identify: %s; outputs written, marked \"interrupted\" and \"converged\": false%s\n",
                   id.result().interrupted_note.c_str(), staged_model ? " (no model exported)" : "");
      return interrupted == SIGALRM ? 1 : 128 + interrupted;
    }
    if (!id.converged())
      std::fprintf(stderr, "scole-identify: %s; outputs written with \"converged\": false\n", id.verdict().c_str());
    return id.exit_code();
  });
}
