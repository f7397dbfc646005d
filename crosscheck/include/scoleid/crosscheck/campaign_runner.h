#pragma once
// Running a campaign (campaign.h): the store of results, one task's execution, the serial driver,
// and the report at the end. The MPI driver (crosscheck/campaign_mpi.cpp, built when MPI is found)
// uses the same pieces, so a campaign gives the same files however many ranks ran it.
//
// The output directory:
//   cases/<case>.json          one per finished case, written atomically (temp file + rename) and
//                              carrying the case's fingerprint: a resumed campaign skips exactly
//                              the cases already stored for the same inputs (a failed case runs
//                              again), and a case killed mid-run left nothing
//   .lock                      held (flock) by the run using the directory
//   truths/<point>-<key>/n<segments>/truth.csv, truth.json   each point's Simbody truth (a
//                              RunDirectory: complete or absent)
//   report.md, cases.csv, points.csv, histogram.csv/.gp/.png, campaign.json   the report, from
//                              the stored cases alone
//   timing.json                who ran what and for how long in the last run (not in the report)
// Under MPI every rank must see the output directory (a shared file system, as on any cluster):
// ranks write truths there and rank 0 writes the case files.
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scoleid/crosscheck/campaign.h"
#include "scoleid/crosscheck/campaign_schedule.h"
#include "scoleid/io/interrupt.h"

namespace scoleid::crosscheck {

struct CampaignRunOptions {
  std::string out;
  bool progress = true;
  // Test of the restart: the process that has finished this many cases exits abruptly (as if
  // killed) in the middle of its next case. -1: never. With MPI, only rank `kill_rank` does.
  int kill_after = -1;
  int kill_rank = -1;  // -1: the last rank
};

// The report's file names (and timing.json): with cases/, truths/ and .lock all a campaign writes.
const std::vector<std::string>& campaign_report_files();

class CampaignStore {
public:
  // Creates the directory (and cases/, truths/) if needed. io::InputError if it cannot, if it
  // holds anything a campaign does not write, or (`exclusive`: the serial run, MPI rank 0) if
  // another run holds its lock (flock on .lock, released when the store is destroyed).
  CampaignStore(const Campaign& c, std::string out, bool exclusive = false);
  ~CampaignStore();
  CampaignStore(const CampaignStore&) = delete;
  CampaignStore& operator=(const CampaignStore&) = delete;
  const std::string& out() const { return out_; }
  // A stored result for case k with case k's fingerprint that did not fail.
  bool case_done(std::size_t k) const;
  // Point p's truth is complete on disk.
  bool truth_done(std::size_t p) const;
  std::string truth_root(std::size_t p) const;
  std::string truth_csv(std::size_t p) const;
  // Writes case k's result atomically.
  void store(std::size_t k, const nlohmann::json& result) const;
  // Every case's stored result, in case order; std::runtime_error naming the first missing.
  std::vector<nlohmann::json> results() const;

private:
  std::string case_path(std::size_t k) const;
  const Campaign& c_;
  std::string out_;
  int lock_fd_ = -1;
};

// The schedule for what the store does not hold yet; the truth's cost is estimated as the point's
// chain segments × simulated duration.
CampaignSchedule make_schedule(const Campaign& c, const CampaignStore& store);

// Runs one task in this process. A case returns its result row (campaign.h's case JSON, with
// "failed": message if its truth is missing or the identification threw); a truth returns {} or
// {"failed": message}. io::Interrupted propagates. `die_midway` (the restart test only): the
// process exits abruptly with the case half done, as if killed. `sweep_threads` > 0 sets the
// identifier's threads per sweep (ObjectiveOptions::sweep_threads; the numbers do not depend on
// it): 1 where several ranks share the machine's cores.
nlohmann::json execute_task(const Campaign& c, const CampaignStore& store, const CampaignTask& task, bool die_midway = false,
                            int sweep_threads = 0);

// One line of progress for a finished case ("p000-s0003: q1 -3.1e-04 ±... covered").
std::string case_line(const Campaign& c, std::size_t k, const nlohmann::json& result);

// What an interrupted campaign says (its stored cases stay, unlike a run directory's outputs).
std::string interrupted_line(const io::Interrupted& e);

// The progress line of a truth handed to `rank` (truths are the long tasks).
void truth_started(const Campaign& c, std::size_t p, int rank);

struct RankTiming {
  double busy_seconds = 0.0;
  int tasks = 0;
};

struct CampaignRunSummary {
  std::size_t cases = 0, done_before = 0, ran = 0, failed = 0;
  double wall_seconds = 0.0;          // from the first task handed out to the last finished
  std::vector<RankTiming> ranks;      // one per rank (1 when serial)
  nlohmann::json tasks = nlohmann::json::array();  // [{task, rank, seconds}]
  double efficiency() const;          // Σ busy / (wall × ranks)
};

// Every unfinished task, in this process.
CampaignRunSummary run_campaign_serial(const Campaign& c, const CampaignStore& store, const CampaignRunOptions& opt);

// The report from the store (and timing.json from `run`), the summary on stdout; the exit code:
// 0 if every case ran, 1 if any failed.
int finish_campaign(const Campaign& c, const CampaignStore& store, const CampaignRunSummary& run, const CampaignRunOptions& opt);

}  // namespace scoleid::crosscheck
