#include "scoleid/crosscheck/campaign_schedule.h"

#include <stdexcept>

namespace scoleid::crosscheck {

CampaignSchedule::CampaignSchedule(std::vector<std::size_t> case_point, std::vector<double> truth_cost,
                                   std::vector<bool> truth_done, std::vector<bool> case_done)
    : case_point_(std::move(case_point)), truth_cost_(std::move(truth_cost)) {
  const std::size_t P = truth_cost_.size(), K = case_point_.size();
  if (truth_done.size() != P || case_done.size() != K) throw std::invalid_argument("CampaignSchedule: sizes differ");
  truth_state_.assign(P, 0);
  truth_needed_.assign(P, false);
  case_state_.assign(K, 0);
  for (std::size_t p = 0; p < P; ++p)
    if (truth_done[p]) truth_state_[p] = 2;
  for (std::size_t k = 0; k < K; ++k) {
    if (case_point_[k] >= P) throw std::invalid_argument("CampaignSchedule: case of an unknown point");
    if (case_done[k]) {
      case_state_[k] = 2;
      ++done_before_;
    } else {
      truth_needed_[case_point_[k]] = true;
    }
  }
}

CampaignSchedule::Next CampaignSchedule::next(CampaignTask& task) {
  // A case whose truth is ready, in case order.
  for (std::size_t k = next_case_; k < case_state_.size(); ++k) {
    if (case_state_[k] != 0 || truth_state_[case_point_[k]] != 2) continue;
    case_state_[k] = 1;
    task = {CampaignTask::Kind::Case, k};
    while (next_case_ < case_state_.size() && case_state_[next_case_] != 0) ++next_case_;
    return Next::Run;
  }
  // The costliest truth still needed and not started (ties: the first point).
  std::size_t best = truth_cost_.size();
  for (std::size_t p = 0; p < truth_cost_.size(); ++p)
    if (truth_needed_[p] && truth_state_[p] == 0 && (best == truth_cost_.size() || truth_cost_[p] > truth_cost_[best])) best = p;
  if (best < truth_cost_.size()) {
    truth_state_[best] = 1;
    task = {CampaignTask::Kind::Truth, best};
    return Next::Run;
  }
  for (int s : case_state_)
    if (s == 0) return Next::Wait;  // cases wait for truths running elsewhere
  return Next::Done;
}

void CampaignSchedule::finished(const CampaignTask& task) {
  if (task.kind == CampaignTask::Kind::Truth)
    truth_state_.at(task.index) = 2;
  else
    case_state_.at(task.index) = 2;
}

std::size_t CampaignSchedule::cases_left() const {
  std::size_t n = 0;
  for (int s : case_state_) n += s != 2 ? 1 : 0;
  return n;
}

}  // namespace scoleid::crosscheck
