#include "scoleid/crosscheck/campaign_runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include "scoleid/crosscheck/case_identification.h"
#include "scoleid/crosscheck/truth_levels.h"
#include "scoleid/identify/run/fit_plot.h"
#include "scoleid/identify/run/problem.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"
#include "scoleid/io/run_directory.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/validation.h"

namespace scoleid::crosscheck {

namespace fs = std::filesystem;
using nlohmann::json;

const std::vector<std::string>& campaign_report_files() {
  static const std::vector<std::string> f = {"report.md", "cases.csv", "points.csv", "histogram.csv", "histogram.gp",
                                             "histogram.png", "campaign.json", "timing.json"};
  return f;
}

CampaignStore::CampaignStore(const Campaign& c, std::string out, bool exclusive) : c_(c), out_(std::move(out)) {
  std::error_code ec;
  // Not inside another run's output (its commit would take this campaign's files with it).
  io::check_not_inside_running(out_, "campaign output directory");
  // Only a campaign's own files may be there: nothing of the user's is ever replaced.
  if (fs::exists(out_, ec)) {
    if (!fs::is_directory(out_, ec)) throw io::InputError("campaign output directory '" + out_ + "': exists and is not a directory");
    for (const auto& e : fs::directory_iterator(out_, ec)) {
      const std::string n = e.path().filename().string();
      const auto& own = campaign_report_files();
      const bool ours = n == "cases" || n == "truths" || n == ".lock" || std::find(own.begin(), own.end(), n) != own.end() ||
                        n.find(".tmp.") != std::string::npos;
      if (!ours)
        throw io::InputError("campaign output directory '" + out_ + "': holds '" + n +
                             "', which a campaign does not write; choose an empty or a campaign's directory");
    }
  }
  fs::create_directories(fs::path(out_) / "cases", ec);
  if (!ec) fs::create_directories(fs::path(out_) / "truths", ec);
  if (ec) throw io::InputError("campaign output directory '" + out_ + "': cannot be created: " + ec.message());
  if (exclusive) {
    // One campaign run per directory at a time (two would race on the truths and the cases).
    const std::string lock = (fs::path(out_) / ".lock").string();
    lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (lock_fd_ < 0) throw io::InputError("campaign output directory '" + out_ + "': cannot be written");
    if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
      ::close(lock_fd_);
      lock_fd_ = -1;
      throw io::InputError("campaign output directory '" + out_ + "': another campaign run is using it");
    }
  }
  // This process works for the campaign: its truths inside out_ are not refused for out_'s lock
  // (the coordinator's, held here, or the coordinator's that an MPI worker's store runs beside).
  io::register_campaign_directory(out_);
}

CampaignStore::~CampaignStore() {
  if (lock_fd_ >= 0) ::close(lock_fd_);
}

std::string CampaignStore::case_path(std::size_t k) const { return (fs::path(out_) / "cases" / (c_.cases.at(k).id + ".json")).string(); }

bool CampaignStore::case_done(std::size_t k) const {
  std::ifstream in(case_path(k));
  if (!in) return false;
  try {
    const json j = json::parse(in);
    // A case that failed is run again: its failure may have been the machine's (a full disk, a
    // truth not yet visible on a shared file system).
    return j.value("key", std::string()) == c_.cases[k].key && !j.contains("failed");
  } catch (const json::exception&) {
    return false;  // unreadable: run it again
  }
}

std::string CampaignStore::truth_root(std::size_t p) const {
  return (fs::path(out_) / "truths" / (c_.points.at(p).id + "-" + c_.points[p].key)).string();
}

std::string CampaignStore::truth_csv(std::size_t p) const {
  return truth_root(p) + "/n" + std::to_string(c_.points.at(p).scenario.truth.segments) + "/truth.csv";
}

bool CampaignStore::truth_done(std::size_t p) const {
  // The truth directory is committed as a whole (io::RunDirectory): its csv means it is complete.
  return fs::is_regular_file(truth_csv(p));
}

void CampaignStore::store(std::size_t k, const json& result) const {
  io::write_text_atomic(case_path(k), result.dump(1) + "\n");
}

std::vector<json> CampaignStore::results() const {
  std::vector<json> v;
  for (std::size_t k = 0; k < c_.cases.size(); ++k) {
    std::ifstream in(case_path(k));
    if (!in) throw std::runtime_error("campaign: no stored result for case " + c_.cases[k].id);
    v.push_back(json::parse(in));
    if (v.back().value("key", std::string()) != c_.cases[k].key)
      throw std::runtime_error("campaign: the stored result of case " + c_.cases[k].id + " is for other inputs");
  }
  return v;
}

CampaignSchedule make_schedule(const Campaign& c, const CampaignStore& store) {
  std::vector<std::size_t> case_point;
  std::vector<bool> case_done, truth_done;
  std::vector<double> cost;
  for (std::size_t k = 0; k < c.cases.size(); ++k) {
    case_point.push_back(c.cases[k].point);
    case_done.push_back(store.case_done(k));
  }
  for (std::size_t p = 0; p < c.points.size(); ++p) {
    truth_done.push_back(store.truth_done(p));
    const auto& s = c.points[p].scenario;
    // The Simbody run's cost grows with the chain and the simulated time (its step is the chain's,
    // not the sampling's).
    cost.push_back(static_cast<double>(s.truth.segments) * s.simulation.duration);
  }
  return CampaignSchedule(case_point, cost, truth_done, case_done);
}

namespace {

json execute_case(const Campaign& c, const CampaignStore& store, std::size_t k, bool die_midway, int sweep_threads) {
  const CampaignCase& kc = c.cases.at(k);
  json row;
  try {
    const std::string csv = store.truth_csv(kc.point);
    if (!fs::is_regular_file(csv)) throw std::runtime_error("the truth of point " + c.points[kc.point].id + " was not produced");
    // The truth is noise-free: the identifier is told the noise it is given, no other.
    io::Scenario sc = c.points[kc.point].scenario;
    for (auto& s : sc.sensors) s.noise_std = 0.0;
    sc.identification.band_mode = io::IdentificationSpec::BandMode::None;  // (the noise added below comes after any band)
    auto p = identify::make_problem(sc, csv);
    if (sweep_threads > 0) p->objective_options.sweep_threads = sweep_threads;
    if (kc.seed >= 0) add_noise(*p, c.noise_relative, case_noise_seed(c, kc));
    if (die_midway) std::_Exit(137);  // the restart test: killed with the case half done
    row = identify_row(std::move(p));
  } catch (const io::Interrupted&) {
    throw;
  } catch (const std::exception& e) {
    row = json{{"failed", io::one_line(e.what())}};
  }
  row["case"] = kc.id;
  row["point"] = c.points[kc.point].id;
  row["seed"] = kc.seed;
  row["key"] = kc.key;
  return row;
}

}  // namespace

json execute_task(const Campaign& c, const CampaignStore& store, const CampaignTask& task, bool die_midway, int sweep_threads) {
  if (task.kind == CampaignTask::Kind::Case) return execute_case(c, store, task.index, die_midway, sweep_threads);
  try {
    const auto& pt = c.points.at(task.index);
    run_truth_levels(pt.scenario, {pt.scenario.truth.segments}, store.truth_root(task.index), true, false);
    return json::object();
  } catch (const io::Interrupted&) {
    throw;
  } catch (const std::exception& e) {
    return json{{"failed", io::one_line(e.what())}};
  }
}

std::string case_line(const Campaign& c, std::size_t k, const json& r) {
  std::string line = c.cases.at(k).id + ":";
  if (r.contains("failed")) return line + " FAILED: " + r["failed"].get<std::string>();
  char buf[160];
  for (const auto& q : r["parameters"]) {
    const double e = q["relative_error"].is_number() ? q["relative_error"].get<double>() : std::nan("");
    std::snprintf(buf, sizeof buf, " %s %+.2e", q["name"].get<std::string>().c_str(), e);
    line += buf;
    if (q["identifiable"].get<bool>() && q["relative_half_width"].is_number()) {
      std::snprintf(buf, sizeof buf, " ±%.1e%s", q["relative_half_width"].get<double>(), q["covered"].get<bool>() ? "" : " (not covered)");
      line += buf;
    } else {
      line += " (not identifiable)";
    }
  }
  return line + (r.value("converged", false) ? "" : "  NOT CONVERGED");
}

void truth_started(const Campaign& c, std::size_t p, int rank) {
  const auto& sc = c.points.at(p).scenario;
  std::fprintf(stderr, "scole-crosscheck campaign: truth of %s (%s): %d segments, %g s, started on rank %d\n", c.points[p].id.c_str(),
               c.points[p].label.c_str(), sc.truth.segments, sc.simulation.duration, rank);
}

std::string interrupted_line(const io::Interrupted& e) {
  return "interrupted by signal " + std::to_string(e.signal()) +
         ": the finished cases are stored; run the campaign again to resume";
}

double CampaignRunSummary::efficiency() const {
  double busy = 0;
  for (const auto& r : ranks) busy += r.busy_seconds;
  return wall_seconds > 0 && !ranks.empty() ? busy / (wall_seconds * static_cast<double>(ranks.size())) : std::nan("");
}

CampaignRunSummary run_campaign_serial(const Campaign& c, const CampaignStore& store, const CampaignRunOptions& opt) {
  CampaignSchedule sched = make_schedule(c, store);
  CampaignRunSummary s;
  s.cases = sched.cases();
  s.done_before = sched.cases_done_before();
  s.ranks.resize(1);
  if (opt.progress && s.done_before)
    std::fprintf(stderr, "scole-crosscheck campaign: %s: %zu of %zu cases already stored, not run again\n", c.name.c_str(),
                 s.done_before, s.cases);
  const auto t0 = std::chrono::steady_clock::now();
  int cases_finished = 0;
  CampaignTask task;
  for (;;) {
    const auto n = sched.next(task);
    if (n == CampaignSchedule::Next::Done) break;
    if (n == CampaignSchedule::Next::Wait) throw std::logic_error("campaign: a serial schedule waits");  // cannot happen
    io::check_interrupt();
    const bool die = opt.kill_after >= 0 && task.kind == CampaignTask::Kind::Case && cases_finished == opt.kill_after;
    if (opt.progress && task.kind == CampaignTask::Kind::Truth) truth_started(c, task.index, 0);
    const auto a = std::chrono::steady_clock::now();
    const json r = execute_task(c, store, task, die);
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
    s.ranks[0].busy_seconds += sec;
    ++s.ranks[0].tasks;
    if (task.kind == CampaignTask::Kind::Case) {
      store.store(task.index, r);
      ++cases_finished;
      ++s.ran;
      s.failed += r.contains("failed") ? 1 : 0;
      s.tasks.push_back({{"task", c.cases[task.index].id}, {"rank", 0}, {"seconds", sec}});
      if (opt.progress)
        std::fprintf(stderr, "scole-crosscheck campaign: [%zu/%zu] %s (%.1f s)\n", s.done_before + s.ran, s.cases,
                     case_line(c, task.index, r).c_str(), sec);
    } else {
      s.tasks.push_back({{"task", "truth " + c.points[task.index].id}, {"rank", 0}, {"seconds", sec}});
      if (opt.progress)
        std::fprintf(stderr, "scole-crosscheck campaign: truth of %s (%s): %s (%.1f s)\n", c.points[task.index].id.c_str(),
                     c.points[task.index].label.c_str(), r.contains("failed") ? ("FAILED: " + r["failed"].get<std::string>()).c_str() : "done", sec);
    }
    sched.finished(task);
  }
  s.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

int finish_campaign(const Campaign& c, const CampaignStore& store, const CampaignRunSummary& run, const CampaignRunOptions& opt) {
  const std::vector<json> results = store.results();
  const auto files = campaign_report(c, results);
  for (const auto& [name, text] : files) io::write_text_atomic((fs::path(store.out()) / name).string(), text);
  // Report files an earlier run wrote and this one does not (a histogram when the noise was dropped).
  for (const auto& n : campaign_report_files())
    if (!files.count(n) && n != "timing.json" && !(n == "histogram.png" && files.count("histogram.gp"))) {
      std::error_code ec;
      fs::remove(fs::path(store.out()) / n, ec);
    }
  json t{{"ranks", run.ranks.size()}, {"cases", run.cases}, {"stored_before", run.done_before}, {"ran", run.ran},
         {"wall_seconds", run.wall_seconds}, {"efficiency", std::isfinite(run.efficiency()) ? json(run.efficiency()) : json()},
         {"busy_seconds", json::array()}, {"tasks_per_rank", json::array()}, {"tasks", run.tasks}};
  for (const auto& r : run.ranks) {
    t["busy_seconds"].push_back(r.busy_seconds);
    t["tasks_per_rank"].push_back(r.tasks);
  }
  io::write_text_atomic((fs::path(store.out()) / "timing.json").string(), t.dump(2) + "\n");
  if (fs::exists(fs::path(store.out()) / "histogram.gp") &&
      identify::render_gnuplot(store.out(), "histogram.gp") == identify::RenderStatus::NoGnuplot && opt.progress)
    std::fprintf(stderr, "scole-crosscheck campaign: gnuplot is not installed: histogram.png not drawn (histogram.gp is written)\n");
  std::size_t failed = 0, converged = 0;
  for (const auto& r : results) {
    failed += r.contains("failed") ? 1 : 0;
    converged += r.value("converged", false) ? 1 : 0;
  }
  std::printf("Campaign %s: %zu points, %zu cases (%zu stored before, %zu run now), %zu converged, %zu failed\n", c.name.c_str(),
              c.points.size(), c.cases.size(), run.done_before, run.ran, converged, failed);
  std::printf("ranks %zu, wall %.1f s, load-balancing efficiency %.3f (busy / (wall x ranks))\n", run.ranks.size(), run.wall_seconds,
              run.efficiency());
  std::printf("report: %s/report.md\n", store.out().c_str());
  return failed ? 1 : 0;
}

}  // namespace scoleid::crosscheck
