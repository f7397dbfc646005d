#pragma once
// Which task runs next in a campaign (campaign.h): dynamic load balancing for cases whose costs
// differ by orders of magnitude. Two kinds of task: the truth of a point (the Simbody run its cases
// share) and one case (an identification on that truth). A rank asks for work when it is free and
// gets, in order: a case whose truth is done (case order), else the costliest truth not yet
// started, else "wait" (truths are running elsewhere), else "done". Tasks finished in an earlier
// run (stored results) are never handed out again. Pure bookkeeping: no I/O, no MPI; the runner
// (campaign_runner.h) serialises the calls.
#include <cstddef>
#include <vector>

namespace scoleid::crosscheck {

struct CampaignTask {
  enum class Kind { Truth, Case };
  Kind kind = Kind::Case;
  std::size_t index = 0;  // the point (Truth) or the case (Case)
};

class CampaignSchedule {
public:
  // case_point[k]: the point of case k; truth_cost[p]: the relative cost of point p's truth;
  // truth_done / case_done: what earlier runs stored.
  CampaignSchedule(std::vector<std::size_t> case_point, std::vector<double> truth_cost, std::vector<bool> truth_done,
                   std::vector<bool> case_done);

  enum class Next { Run, Wait, Done };
  Next next(CampaignTask& task);
  // A handed-out task has ended (successfully or not: a case that failed is stored as failed; a
  // truth that failed makes its cases fail fast).
  void finished(const CampaignTask& task);

  std::size_t cases() const { return case_point_.size(); }
  std::size_t cases_done_before() const { return done_before_; }
  std::size_t cases_left() const;  // not yet finished (handed out or not)

private:
  std::vector<std::size_t> case_point_;
  std::vector<double> truth_cost_;
  std::vector<int> truth_state_;  // 0 not needed/not started, 1 running, 2 done
  std::vector<bool> truth_needed_;
  std::vector<int> case_state_;   // 0 waiting, 1 running, 2 done
  std::size_t done_before_ = 0, next_case_ = 0;
};

}  // namespace scoleid::crosscheck
