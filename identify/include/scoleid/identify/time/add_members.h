#pragma once
// Counters and timings that sum over solves: the named members of `from` added to those of `to`
// (SolverSummary and ObjectiveCounters accumulate one solve's or one level's counts this way).
namespace scoleid::identify {

template <class T, class... M>
void add_members(T& to, const T& from, M T::*... member) {
  ((to.*member += from.*member), ...);
}

}  // namespace scoleid::identify
