// scole-crosscheck: the Simbody truth against the FE identifier (docs/theory.md §11).
//   scole-crosscheck modes        --scenario X [--out DIR]   natural modes side by side, MAC
//   scole-crosscheck trajectories --scenario X [--out DIR]   the same inputs through both models
//   scole-crosscheck identify     --scenario X [--out DIR]   identification on the truth, extrapolated in n
//   scole-crosscheck report       [--scenario X] [--out DIR] report.md and plots from the above
//   scole-crosscheck all          --scenario X [--out DIR]   the four, then the one-screen summary
//   scole-crosscheck suite        [--only F] [--out DIR]     the mismatch suite (crosscheck/mismatch/*.yaml):
//                                 errors, reported intervals, coverage, sharpness; report.md
//   scole-crosscheck campaign FILE [--out DIR]             scenarios x grid x noise seeds, serially or
//                                 over MPI ranks (mpirun -n K), resumable; report.md, histogram
// DIR defaults to run/<scenario>/crosscheck. Each verb replaces only its own files there, as one
// unit (io/run_directory.h). Exit codes: 0 success; 1 a run failed or an identification did not
// converge (its outputs are written and say so); 2 bad usage or bad input (nothing written);
// 130/143 interrupted (nothing written; a campaign keeps the cases it has stored).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>

#include "campaign_mpi.h"
#include "scoleid/io/output_paths.h"
#include "scoleid/io/program.h"
#include "scoleid/crosscheck/campaign_runner.h"
#include "scoleid/crosscheck/identify_study.h"
#include "scoleid/crosscheck/mismatch_suite.h"
#include "scoleid/crosscheck/modes.h"
#include "scoleid/crosscheck/report.h"
#include "scoleid/crosscheck/trajectories.h"
#include "scoleid/identify/door/scenario_door.h"
#include "scoleid/identify/fe/structure.h"
#include "scoleid/identify/run/fit_plot.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/run_directory.h"
#include "scoleid/io/validation.h"

using namespace scoleid;
namespace fs = std::filesystem;

namespace {
const std::vector<std::string> kOutputs = {
    "modes.csv",   "mac.csv",   "modes.json",  "modal-data.csv",   "trajectories.csv", "trajectories.json",   "overlay.csv",
    "identify.csv", "identify.json", "report.md", "modes_convergence.csv", "identify_convergence.csv",
    "modes.gp",    "modes.png", "overlay.gp",   "overlay.png",      "identify.gp",         "identify.png",
    "truths"};

void print(const crosscheck::Table& t, bool quiet) {
  if (!quiet) std::fputs((t.text() + "\n").c_str(), stdout);
}

// Report files into the staging area; gnuplot is run there (it reads the CSVs beside it).
void write_report(io::RunDirectory& dir, const crosscheck::ReportInputs& in, bool quiet) {
  const bool overlay = fs::exists(dir.path("overlay.csv"));
  const crosscheck::ReportFiles rf = crosscheck::make_report(in, overlay);
  // Carried-over plots are hard links to the earlier run's files: unlink them, so that gnuplot
  // writes new files instead of rewriting the earlier run's in place.
  for (const char* png : {"modes.png", "overlay.png", "identify.png"}) fs::remove(dir.path(png));
  for (const auto& [name, text] : rf.files) io::write_text_atomic(dir.path(name), text);
  int missing = 0;
  for (const auto& s : rf.scripts) {
    const auto st = identify::render_gnuplot(dir.staging(), s);
    if (st == identify::RenderStatus::NoGnuplot) ++missing;
    else if (st == identify::RenderStatus::Failed && !quiet)
      std::fprintf(stderr, "scole-crosscheck: gnuplot failed on %s (the CSV and the script are written)\n", s.c_str());
  }
  if (missing && !quiet)
    std::fprintf(stderr, "scole-crosscheck: gnuplot is not installed: plots not drawn (the .gp scripts are written)\n");
}
// Runs a verb; what escapes it becomes the exit code of the footer (io/program.h).
int guarded(const std::function<int()>& verb) { return io::guarded_main("scole-crosscheck", verb); }

// What a suite run leaves in --out when it ends before its result is written (a failure or a
// signal): the directories it created itself. The family's truth directory is its own and goes
// whole; the shared ones (--out, results/, truths/: other families may be running into them at the
// same time, as under ctest) go only when empty.
class SuiteCleanup {
public:
  SuiteCleanup(const fs::path& out, const std::vector<crosscheck::SuiteFile>& files) {
    for (const fs::path& p : {out, out / "results", out / "truths"}) note(p, false);
    for (const auto& f : files) note(out / "truths" / f.family, true);
  }
  ~SuiteCleanup() {
    if (done_) return;
    std::error_code ec;
    for (auto it = created_.rbegin(); it != created_.rend(); ++it) {
      if (it->second) fs::remove_all(it->first, ec);
      else fs::remove(it->first, ec);  // fails, as wanted, when not empty
    }
  }
  void dismiss() { done_ = true; }
  // A family whose result is written: its truths, and the directories holding them, stay.
  void keep(const fs::path& family_truths) {
    created_.erase(std::remove_if(created_.begin(), created_.end(),
                                  [&](const auto& c) { return !c.second || c.first == family_truths; }),
                   created_.end());
  }

private:
  void note(const fs::path& p, bool own) {
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(p, ec))) created_.push_back({p, own});
  }
  std::vector<std::pair<fs::path, bool>> created_;
  bool done_ = false;
};

// An --out for suite runs holds only what the suite writes there.
void check_suite_out(const fs::path& out) {
  std::error_code ec;
  if (fs::is_symlink(fs::symlink_status(out, ec)))
    throw io::InputError("output directory '" + out.string() + "': is a symbolic link; give the directory itself");
  if (!fs::exists(out, ec)) return;
  if (!fs::is_directory(out, ec)) throw io::InputError("output directory '" + out.string() + "': exists and is not a directory");
  static const std::vector<std::string> ours = {"results", "truths", "report.md", "suite.csv", "suite.json", "suite.gp",
                                                "suite.png"};
  std::vector<std::string> foreign;
  for (const auto& e : fs::directory_iterator(out, ec)) {
    const std::string n = e.path().filename().string();
    if (std::find(ours.begin(), ours.end(), n) == ours.end() && n.find(".tmp.") == std::string::npos) foreign.push_back(n);
  }
  // results/ holds one <family>.json per family run: anything else there is not the suite's either.
  if (fs::is_directory(out / "results", ec))
    for (const auto& e : fs::directory_iterator(out / "results", ec)) {
      const std::string n = e.path().filename().string();
      if (!(e.is_regular_file() && e.path().extension() == ".json") && n.find(".tmp.") == std::string::npos)
        foreign.push_back("results/" + n);
    }
  if (!foreign.empty()) {
    std::sort(foreign.begin(), foreign.end());
    std::string list;
    for (std::size_t i = 0; i < foreign.size() && i < 3; ++i) list += (i ? ", " : "") + foreign[i];
    if (foreign.size() > 3) list += ", ...";
    throw io::InputError("output directory '" + out.string() + "': holds files that are not the suite's (" + list +
                         "); give a new or empty directory, or one holding only earlier suite outputs");
  }
}

// scole-crosscheck suite: see --help.
int run_suite(const std::vector<std::string>& only, const std::string& suite_dir, const std::string& out, bool collect,
              crosscheck::SuiteOptions so, bool quiet) {
  so.progress = !quiet;
  return guarded([&] {
    if (so.seeds != 0 && so.seeds < 2) throw io::InputError("--seeds must be at least 2 (a scatter needs two draws), got " + std::to_string(so.seeds));
    // Every file is read and checked before anything runs, the identifier's model of each case
    // built once: bad input costs nothing and writes nothing.
    std::vector<crosscheck::SuiteFile> files;
    if (!collect || !only.empty()) {
      std::vector<std::string> paths;
      if (only.empty()) paths = crosscheck::suite_files(suite_dir);
      for (const auto& o : only) {
        if (fs::exists(o)) { paths.push_back(o); continue; }
        const fs::path p = fs::path(suite_dir) / (o + ".yaml");
        bool found = fs::exists(p);
        if (found) paths.push_back(p.string());
        else
          for (const auto& f : crosscheck::suite_files(suite_dir))
            if (crosscheck::load_suite_file(f).family == o) { paths.push_back(f); found = true; }
        if (!found) throw io::InputError("--only: '" + o + "' is neither a suite file nor a family in " + suite_dir);
      }
      if (paths.empty()) throw io::InputError("suite directory '" + suite_dir + "': no *.yaml family files");
      for (const auto& p : paths) {
        files.push_back(crosscheck::load_suite_file(p));
        for (const auto& f : files)
          if (&f != &files.back() && f.family == files.back().family)
            throw io::InputError("suite file '" + p + "': family '" + f.family + "' is also the family of '" + f.path + "'");
        for (std::size_t k = 0; k < files.back().cases.size(); ++k) {
          identify::check_identification(crosscheck::case_scenario(files.back(), k));
        }
      }
    }
    check_suite_out(out);
    SuiteCleanup cleanup(out, files);
    if (!files.empty()) fs::create_directories(fs::path(out) / "results");  // (--collect alone writes none)
    bool ok = true;
    for (const auto& f : files) {
      const auto r = crosscheck::run_suite_file(f, out, so);
      io::write_json_atomic((fs::path(out) / "results" / (f.family + ".json")).string(), r);
      cleanup.keep(fs::path(out) / "truths" / f.family);
      ok = ok && r["expectations_met"].get<bool>();
      if (!quiet)
        for (const auto& c : r["checks"])
          if (!c["held"].get<bool>())
            std::fprintf(stderr, "scole-crosscheck suite: %s: expectation failed: %s (measured %s)\n", f.family.c_str(),
                         c["what"].get<std::string>().c_str(), c["measured"].get<std::string>().c_str());
    }
    cleanup.dismiss();
    if (!only.empty() && !collect) {
      if (!quiet) std::fprintf(stderr, "scole-crosscheck suite: wrote %s/results; %s\n", out.c_str(), ok ? "expectations held" : "NOT every expectation held");
      return ok ? 0 : 1;
    }
    std::vector<nlohmann::json> results;
    // One result per family of the suite directory (a family without one has not been run: that
    // is an incomplete suite, not a smaller one).
    std::vector<std::string> missing, families;
    for (const auto& p : crosscheck::suite_files(suite_dir)) families.push_back(crosscheck::load_suite_file(p).family);
    for (const auto& f : files)
      if (std::find(families.begin(), families.end(), f.family) == families.end()) families.push_back(f.family);
    for (const auto& fam : families) {
      const fs::path r = fs::path(out) / "results" / (fam + ".json");
      if (fs::exists(r)) {
        results.push_back(io::read_json(r.string()));
        crosscheck::check_suite_result(results.back(), r.string());
      }
      else missing.push_back(fam);
    }
    if (!missing.empty()) {
      std::string m;
      for (const auto& f : missing) m += (m.empty() ? "" : ", ") + f;
      throw io::InputError("output directory '" + out + "': no results/<family>.json for: " + m + " (run them first)");
    }
    if (results.empty()) throw io::InputError("output directory '" + out + "': no results/*.json to summarise");
    const auto s = crosscheck::summarise_suite(results);
    for (const auto& [name, text] : crosscheck::suite_report(results, s))
      io::write_text_atomic((fs::path(out) / name).string(), text);
    if (identify::render_gnuplot(out, "suite.gp") == identify::RenderStatus::NoGnuplot && !quiet)
      std::fprintf(stderr, "scole-crosscheck: gnuplot is not installed: suite.png not drawn (suite.gp is written)\n");
    std::printf("Mismatch suite: %zu families, %d estimates\n", results.size(), s.cases);
    std::printf("  coverage  %d of %d = %.1f %% (target >= 90 %%)\n", s.covered, s.cases, 100.0 * s.coverage);
    std::printf("  sharpness median half-width %.3g / median error %.3g = %.2f (target <= 10)\n", s.median_relative_half_width,
                s.median_relative_error, s.sharpness);
    std::printf("  expectations of the family files: %s\n", s.expectations_met ? "all held" : "NOT all held");
    for (const auto& f : s.failures) std::printf("    failed: %s\n", f.c_str());
    std::printf("  report: %s/report.md\n", out.c_str());
    const bool targets = s.coverage >= 0.9 && s.sharpness <= 10.0;
    return ok && s.expectations_met && targets ? 0 : 1;
  });
}

// The number of ranks when an MPI launcher (mpirun, srun) started this process, else 0; `rank`
// this process's rank.
int launched_ranks(int* rank) {
  auto env = [](const char* k) { const char* v = std::getenv(k); return v ? std::atoi(v) : -1; };
  *rank = std::max({env("OMPI_COMM_WORLD_RANK"), env("PMI_RANK"), env("PMIX_RANK"), env("SLURM_PROCID"), 0});
  const int n = std::max({env("OMPI_COMM_WORLD_SIZE"), env("PMI_SIZE"), env("SLURM_NTASKS") > 1 ? env("SLURM_NTASKS") : -1});
  if (n > 0) return n;
  return std::getenv("PMIX_RANK") ? 1 : 0;  // PMIx does not always state the size; MPI will
}

// scole-crosscheck campaign: see --help.
int run_campaign(const std::string& file, crosscheck::CampaignRunOptions opt) {
  int rank = 0;
  const int ranks = launched_ranks(&rank);
  if (ranks > 0) {
#ifdef SCOLEID_HAVE_MPI
    return crosscheck::run_campaign_mpi(file, opt);
#else
    if (ranks > 1) {
      if (rank == 0)
        std::fprintf(stderr, "scole-crosscheck: campaign: started by an MPI launcher with %d ranks, but this build has no MPI "
                             "(install libopenmpi-dev and reconfigure); run it without mpirun to run serially\n", ranks);
      return 2;
    }
#endif
  }
  return guarded([&] {
    const crosscheck::Campaign c = crosscheck::load_campaign(file);
    if (opt.out.empty()) opt.out = "run/campaign/" + c.name;
    io::check_inputs_outside("--out", opt.out, {file});
    const crosscheck::CampaignStore store(c, opt.out, true);
    if (opt.progress) std::fprintf(stderr, "scole-crosscheck campaign: %s: %zu points, %zu cases, serially\n", c.name.c_str(), c.points.size(), c.cases.size());
    try {
      const auto run = crosscheck::run_campaign_serial(c, store, opt);
      return crosscheck::finish_campaign(c, store, run, opt);
    } catch (const io::Interrupted& e) {
      std::fprintf(stderr, "\nscole-crosscheck: %s\n", crosscheck::interrupted_line(e).c_str());
      return e.exit_code();
    }
  });
}

// The command line: the verbs and their options.
struct Cli {
  std::string scenario = "paper-scole-1", out;
  bool out_given = false;  // --out was on the command line (an empty one is refused, not defaulted)
  bool quiet = false;
  crosscheck::ModesOptions mo;
  crosscheck::TrajectoryOptions to;
  crosscheck::IdentifyStudyOptions io_;
  std::vector<std::string> suite_only;
  std::string suite_dir = SCOLEID_MISMATCH_DIR, suite_out = "run/mismatch-suite";
  bool suite_collect = false;
  crosscheck::SuiteOptions so;
  std::string campaign_file;
  crosscheck::CampaignRunOptions co;
  CLI::App *modes = nullptr, *traj = nullptr, *ident = nullptr, *report = nullptr, *all = nullptr, *suite = nullptr,
           *camp = nullptr;
};

void add_verbs(CLI::App& app, Cli& c) {
  auto common = [&](CLI::App* sub) {
    sub->add_option("-s,--scenario", c.scenario, "built-in scenario name or YAML file")->capture_default_str();
    sub->add_option("-o,--out", c.out, "output directory (default: run/<scenario>/crosscheck)");
    sub->add_flag("-q,--quiet", c.quiet, "no tables on stdout, no progress on stderr");
  };
  auto* modes = c.modes = app.add_subcommand(
      "modes", "natural frequencies and mode shapes: the Simbody chain linearised at rest at n, 2n, 4n segments against "
               "the FE model at N, 2N, 4N elements and the analytic values where they exist; observed rates, Richardson "
               "extrapolation of the chain, MAC matrix. Writes modes.csv, mac.csv, modes.json, and modal-data.csv (the chain's modes at the scenario's displacement-type sensors, stds from its lumping error: measured modes for scole-identify --experiments)");
  common(modes);
  modes->add_option("--segments", c.mo.segments, "first chain resolution n (default: the scenario's truth.segments)");
  modes->add_option("--elements", c.mo.elements, "first FE resolution N (default: the scenario's identification.elements)");
  modes->add_option("--count", c.mo.count, "flexible modes compared")->capture_default_str();
  modes->add_option("--levels", c.mo.levels, "resolutions per side (n, 2n, 4n: 3)")->capture_default_str();
  auto* traj = c.traj = app.add_subcommand(
      "trajectories", "the scenario's inputs through both models at the truth's parameters: relative RMS difference "
                      "per sensor at n, 2n, 4n segments and its rate. Writes trajectories.csv, trajectories.json, "
                      "overlay.csv, truths/");
  common(traj);
  traj->add_option("--segments", c.to.segments, "first chain resolution n (default: the scenario's truth.segments)");
  traj->add_option("--elements", c.to.elements, "FE elements (default: 4 x identification.elements)");
  traj->add_option("--fe-step", c.to.fe_step, "FE time step (default: resolve the first 5 flexible modes with omega h <= 0.03)");
  traj->add_option("--levels", c.to.levels, "chain resolutions (n, 2n, 4n: 3)")->capture_default_str();
  traj->add_flag("--nonlinear", c.to.nonlinear,
                 "SCOLE: also the nonlinear FE model (finite shuttle rotation, the mast in the rotating frame), its "
                 "difference to the chain beside the linear model's");
  traj->add_option("--nonlinear-elements", c.to.nonlinear_elements,
                   "elements of the nonlinear FE model (default: as the linear one)");
  auto* ident = c.ident = app.add_subcommand(
      "identify", "the identifier on the Simbody truth at n, 2n, 4n segments, the estimates' errors against the "
                  "truth's values, their extrapolation in n, and the FE-on-FE result beside them. Writes identify.csv, "
                  "identify.json, truths/");
  common(ident);
  ident->add_option("--segments", c.io_.segments, "first chain resolution n (default: the scenario's truth.segments)");
  ident->add_option("--levels", c.io_.levels, "chain resolutions (n, 2n, 4n: 3)")->capture_default_str();
  ident->add_flag("--with-noise", c.io_.with_noise, "keep the scenario's sensor noise in the truths (default: noise-free)");
  auto* report = c.report = app.add_subcommand("report", "report.md with every table, a CSV behind each, and PNG plots, from the "
                                              "JSON the other verbs left in --out");
  common(report);
  auto* all = c.all = app.add_subcommand("all", "modes, trajectories, identify and report, then the one-screen summary");
  common(all);
  auto* suite = c.suite = app.add_subcommand(
      "suite", "the mismatch suite: each family file (truth differing from the identifier's model by a stated mismatch) "
               "runs the truth and the identifier; per family <family>.json under --out/results with each case's errors, "
               "reported intervals and the file's expectations; then report.md, suite.csv, suite.json and suite.png "
               "(error and interval against mismatch size) with the coverage (truth inside the interval, target >= 90 %) "
               "and the sharpness (median interval / median error, target <= 10). Exit 1 when an expectation or a "
               "target fails (outputs written, marked).");
  suite->add_option("--only", c.suite_only, "run only these families (file path or family name); no report unless --collect is given too (the report then covers every family of --suite-dir)")
      ->take_all();
  suite->add_option("--suite-dir", c.suite_dir, "directory of the family files")->capture_default_str();
  suite->add_option("-o,--out", c.suite_out, "output directory")->capture_default_str();
  suite->add_option("--seeds", c.so.seeds, "noise seeds per noise case (default: the file's)");
  suite->add_flag("--collect", c.suite_collect, "only summarise the results already in --out/results: report, coverage, sharpness");
  suite->add_flag("-q,--quiet", c.quiet, "no progress on stderr");
  auto* camp = c.camp = app.add_subcommand(
      "campaign", "a campaign file: scenarios x a parameter grid x noise seeds, each point's Simbody truth once and "
                  "its identifications (noise-free and one per seed); per-case results stored atomically under "
                  "--out/cases (a second run resumes: stored cases are not run again); then report.md (per point: "
                  "error, seed scatter against the reported std, interval coverage), cases.csv, points.csv, "
                  "histogram.png, campaign.json, and timing.json. Serial by default; started by `mpirun -n K` (or "
                  "srun) the cases are shared out dynamically over the K ranks, the report identical. Exit 1 when a "
                  "case failed.");
  camp->add_option("file", c.campaign_file, "the campaign file (YAML)")->required();
  camp->add_option("-o,--out", c.co.out, "output directory (default: run/campaign/<campaign name>)");
  camp->add_flag("-q,--quiet", c.quiet, "no progress on stderr");
  camp->add_option("--kill-after", c.co.kill_after, "restart test: exit abruptly during the case after this many")->group("");
  camp->add_option("--kill-rank", c.co.kill_rank, "restart test: the rank that exits (default the last)")->group("");
}

// modes: the chain against the FE model and the analytic values (modes.csv, mac.csv, modes.json),
// and the chain's modes as measured modes for scole-identify --experiments (modal-data.csv; a
// scenario without a displacement-type sensor has no shapes to write).
void modes_verb(io::RunDirectory& dir, const io::Scenario& sc, const crosscheck::ModesOptions& mo, bool quiet) {
  if (!quiet) std::fprintf(stderr, "scole-crosscheck: modes of %s\n", sc.name.c_str());
  const auto r = crosscheck::compare_modes(sc, mo);
  const auto t = crosscheck::modes_table(r), m = crosscheck::mac_table(r);
  print(t, quiet);
  print(m, quiet);
  io::write_text_atomic(dir.path("modes.csv"), t.csv());
  io::write_text_atomic(dir.path("mac.csv"), m.csv());
  io::write_json_atomic(dir.path("modes.json"), crosscheck::to_json(r));
  try {
    io::write_modal_data(dir.path("modal-data.csv"),
                         crosscheck::chain_modal_data(sc, r.segments.front(), static_cast<int>(r.modes.size())));
  } catch (const io::InputError& e) {
    std::fprintf(stderr, "scole-crosscheck: note: no modal-data.csv: %s\n", io::one_line(e.what()).c_str());
  }
}

// trajectories: both models through the scenario's inputs; returns the noise-free truths it ran.
std::vector<crosscheck::TruthLevel> trajectories_verb(io::RunDirectory& dir, const io::Scenario& sc,
                                                      const crosscheck::TrajectoryOptions& to, bool quiet) {
  const auto r = crosscheck::compare_trajectories(sc, to, dir.path("truths"));
  const auto t = crosscheck::trajectories_table(r);
  print(t, quiet);
  io::write_text_atomic(dir.path("trajectories.csv"), t.csv());
  io::write_text_atomic(dir.path("overlay.csv"), crosscheck::overlay_table(r).csv());
  io::write_json_atomic(dir.path("trajectories.json"), crosscheck::to_json(r));
  return r.truths;
}

// identify: the identifier on the truths. The trajectories' noise-free truths serve when the levels
// match; the study runs its own otherwise (replacing them: truths/ then holds what identify.json
// used). Returns whether every identification converged.
bool identify_verb(io::RunDirectory& dir, const io::Scenario& sc, const crosscheck::IdentifyStudyOptions& io_, bool quiet,
                   const std::vector<crosscheck::TruthLevel>& noise_free_truths) {
  const auto s = crosscheck::identify_study(sc, io_, dir.path("truths"), noise_free_truths);
  const auto t = crosscheck::identify_table(s);
  print(t, quiet);
  io::write_text_atomic(dir.path("identify.csv"), t.csv());
  io::write_json_atomic(dir.path("identify.json"), crosscheck::to_json(s));
  if (!s.all_converged()) std::fprintf(stderr, "scole-crosscheck: not every identification converged (identify.json: runs)\n");
  return s.all_converged();
}

// report: from the JSON this and earlier runs left. The earlier outputs are read from the staging
// copy; a file that does not hold what this program writes is named as the user's file in --out.
std::vector<std::string> report_verb(io::RunDirectory& dir, const std::string& out, bool quiet) {
  try {
    const crosscheck::ReportInputs in = crosscheck::read_report_inputs(dir.staging());
    if (in.modes.is_null() && in.trajectories.is_null() && in.identify.is_null())
      throw io::InputError("output directory '" + out + "': no modes.json, trajectories.json or identify.json to report on");
    std::vector<std::string> lines = crosscheck::summary_lines(in);
    write_report(dir, in, quiet);
    return lines;
  } catch (const nlohmann::json::exception& e) {
    throw io::InputError("output directory '" + out + "': modes.json, trajectories.json or identify.json is not as " +
                         "scole-crosscheck writes it (" + io::one_line(e.what()) + ")");
  } catch (const io::InputError& e) {
    std::string m = e.what();
    for (std::size_t at; (at = m.find(dir.staging())) != std::string::npos;) m.replace(at, dir.staging().size(), out);
    throw io::InputError(m);
  }
}

// The scenario verbs (modes, trajectories, identify, report, all) into one output directory.
int run_scenario_verbs(Cli& c) {
  const io::Scenario sc = io::load_scenario(c.scenario);
  io::validate_scenario(sc);
  if (c.out_given && c.out.empty()) throw io::InputError("command line: --out is empty (give a value, or leave the option out)");
  if (c.out.empty()) c.out = "run/" + sc.name + "/crosscheck";
  std::string why;
  if (!c.mo.IsValid(&why) || !c.to.IsValid(&why) || !c.io_.IsValid(&why)) throw io::InputError("command line: " + why);
  c.to.progress = c.io_.progress = !c.quiet;
  io::check_inputs_outside("--out", c.out, {c.scenario});
  io::RunDirectory dir(c.out, kOutputs, "scole-crosscheck");
  const bool all = c.all->parsed();
  bool converged = true;
  if (c.modes->parsed() || all) modes_verb(dir, sc, c.mo, c.quiet);
  std::vector<crosscheck::TruthLevel> noise_free_truths;
  if (c.traj->parsed() || all) noise_free_truths = trajectories_verb(dir, sc, c.to, c.quiet);
  if (c.ident->parsed() || all) converged = identify_verb(dir, sc, c.io_, c.quiet, noise_free_truths);
  dir.keep_earlier_outputs();
  if (c.report->parsed() || all) {
    const std::vector<std::string> lines = report_verb(dir, c.out, c.quiet);
    if (all || !c.quiet) {
      std::printf("Cross-check of %s\n", sc.name.c_str());
      for (const auto& l : lines) std::printf("  %s\n", l.c_str());
    }
  }
  dir.commit();
  if (!c.quiet) std::fprintf(stderr, "scole-crosscheck: wrote %s\n", c.out.c_str());
  return converged ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // tables and progress interleave in order in a log
  CLI::App app{
      "scole-crosscheck: the Simbody truth (a chain of n rigid segments) against the finite-element identifier\n"
      "(N elements), on the same scenario: natural modes, trajectories, and identification on the truth with the\n"
      "chain's lumping bias extrapolated away. Tables on stdout; CSV and JSON beside them in --out\n"
      "(default run/<scenario>/crosscheck); `report` adds report.md and PNG plots (gnuplot)."};
  app.require_subcommand(1, 1);
  app.footer(
      "Exit codes: 0 success; 1 a run failed or an identification did not converge (outputs written, marked); 2 bad "
      "usage or bad input (nothing written); 130/143 interrupted (nothing written). Each verb replaces only its own "
      "files in the output directory, all at once.");
  Cli c;
  add_verbs(app, c);
  if (const auto code = io::parse_command_line(app, argc, argv, "scole-crosscheck")) return *code;
  io::install_interrupt_handlers();
  if (c.camp->parsed()) {
    c.co.progress = !c.quiet;
    return run_campaign(c.campaign_file, c.co);
  }
  if (c.suite->parsed()) return run_suite(c.suite_only, c.suite_dir, c.suite_out, c.suite_collect, c.so, c.quiet);
  for (CLI::App* sub : {c.modes, c.traj, c.ident, c.report, c.all})
    if (sub && sub->parsed() && sub->count("--out") > 0) c.out_given = true;
  return guarded([&] { return run_scenario_verbs(c); });
}
