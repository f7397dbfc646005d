#include "scoleid/identify/time/checkpoints.h"

#include <algorithm>
#include <stdexcept>
#include <limits>

namespace scoleid::identify {

using Eigen::VectorXd;

void CheckpointRecorder::operator()(const SecondOrderSolver::Point& pt) {
  if (!pt.resumable) return;
  if (!ckpts_.empty() && ++since_ < spacing_) return;
  since_ = 0;
  Checkpoint c;
  c.t = pt.t;
  c.origin = pt.origin;
  c.h = pt.h;
  c.x = Eigen::Map<const VectorXd>(pt.x, n_);
  c.v = Eigen::Map<const VectorXd>(pt.v, n_);
  c.a = Eigen::Map<const VectorXd>(pt.a, n_);
  ckpts_.push_back(std::move(c));
}

WindowedSink::WindowedSink(int n, std::size_t points, Visit visit, int columns)
    : n_(n * std::max(columns, 1)), columns_(std::max(columns, 1)), points_(std::max<std::size_t>(points, 2)),
      visit_(std::move(visit)), window_(n_) {}

void WindowedSink::operator()(const SecondOrderSolver::Point& pt) {
  // Columns are stored one after another (n × columns, column-major), so the first `columns_` of
  // them are the first n_ numbers.
  if (pt.columns < columns_) throw std::logic_error("WindowedSink: a point without the columns the window holds");
  if (window_.size() >= points_ && pt.t > window_.t_end()) {
    visit_(window_);
    Trajectory next(n_);
    const std::size_t k = window_.size() - 1;
    next.push(window_.t_end(), window_.x(k).data(), window_.v(k).data(), window_.a(k).data());
    window_ = std::move(next);
  }
  window_.push(pt.t, pt.x, pt.v, pt.a);
}

void WindowedSink::finish() {
  if (window_.size() > 0) visit_(window_);
  window_ = Trajectory(n_);
}

void sample_streamed(const SecondOrderSolver& solver, double t0, double t1, const SecondOrderSolver::Forcing& forcing,
                     const std::vector<double>& breakpoints, const std::vector<double>& times, const SampleVisit& at,
                     SolverSummary* summary, std::size_t points, const SecondOrderSolver::InitialState* initial) {
  const int n = solver.dim();
  VectorXd x(n), v(n);
  std::size_t next = 0;
  bool last = false;
  WindowedSink sink(n, points, [&](const Trajectory& w) {
    while (next < times.size() && (last || times[next] <= w.t_end())) {
      w.eval(times[next], x.data(), v.data());
      at(next, x, v);
      ++next;
    }
  });
  solver.stream(t0, t1, forcing, breakpoints, [&](const SecondOrderSolver::Point& pt) { sink(pt); }, summary, nullptr,
                std::numeric_limits<double>::infinity(), StepAnchor::Start, initial);
  last = true;  // the final window also takes the times beyond the run (clamped)
  sink.finish();
}

CheckpointedState::CheckpointedState(const SecondOrderSolver& solver, const SecondOrderSolver::Forcing& forcing,
                                     std::vector<double> breakpoints, double t_end, std::vector<Checkpoint> checkpoints)
    : solver_(solver), forcing_(forcing), breakpoints_(std::move(breakpoints)), t_end_(t_end), ckpts_(std::move(checkpoints)) {
  if (ckpts_.empty()) throw std::invalid_argument("CheckpointedState: no checkpoints");
}

Trajectory CheckpointedState::solve_segment(std::size_t c) {
  const Checkpoint& k = ckpts_[c];
  const double until = c + 1 < ckpts_.size() ? ckpts_[c + 1].t : t_end_;
  Trajectory u(static_cast<int>(k.x.size()));
  SecondOrderSolver::Start start{k.t, k.origin, k.h, k.x.data(), k.v.data(), k.a.data()};
  SolverSummary sum;
  if (k.t < t_end_) {
    solver_.stream(k.t, t_end_, forcing_, breakpoints_,
                   [&u](const SecondOrderSolver::Point& pt) { u.push(pt.t, pt.x, pt.v, pt.a); }, &sum, &start, until);
  } else {
    u.push(k.t, k.x.data(), k.v.data(), k.a.data());
  }
  summary_.Accumulate(sum);
  ++resolves_;
  return u;
}

void CheckpointedState::cover(double ta, double tb) {
  // Segment c holds [t_c, t_{c+1}]; the ones meeting [ta, tb] (any number: short segments around
  // breakpoints can make a window span several).
  auto first = std::upper_bound(ckpts_.begin(), ckpts_.end(), ta, [](double t, const Checkpoint& k) { return t < k.t; });
  const std::size_t c0 = first == ckpts_.begin() ? 0 : static_cast<std::size_t>(first - ckpts_.begin()) - 1;
  std::size_t c1 = c0;
  while (c1 + 1 < ckpts_.size() && ckpts_[c1 + 1].t < tb) ++c1;
  for (auto it = segments_.begin(); it != segments_.end();) it = it->first < c0 || it->first > c1 ? segments_.erase(it) : std::next(it);
  for (std::size_t c = c0; c <= c1; ++c)
    if (!segments_.count(c)) segments_.emplace(c, solve_segment(c));
}

void CheckpointedState::eval(double t, double* x, double* v, double* a) const {
  // The first covered segment that reaches t (segments are in time order).
  const Trajectory* u = nullptr;
  for (const auto& [c, seg] : segments_) {
    u = &seg;
    if (t <= seg.t_end()) break;
  }
  if (!u) throw std::logic_error("CheckpointedState::eval before cover()");
  u->eval(t, x, v, a);
}

void CheckpointedState::times_in(double ta, double tb, std::vector<double>& out) const {
  for (const auto& [c, u] : segments_)
    for (double t : u.times())
      if (t >= ta && t <= tb) out.push_back(t);
}

}  // namespace scoleid::identify
