#pragma once
// Checkpointing of a streamed solve (docs/theory.md §7.9).
//
// The costate runs backward in time and the gradient quadrature ∫ pᵀ ∂R/∂q dt needs the state and
// the costate at the same instants. Storing the whole state costs steps × DOF × 3 numbers. Instead
// the forward run keeps the state at every L-th recorded point (a checkpoint: t, the step grid's
// origin and h, x, v, a), and the backward pass re-solves the state between two checkpoints when
// it needs it (SecondOrderSolver::stream resumed from a checkpoint reproduces the original points
// bit for bit). The costate itself is streamed in windows of L points, so the memory is
//     (steps / L) checkpoints + 2 state segments + 1 costate window  ≈  (steps/L + 3L) × DOF × 3,
// smallest at L ≈ √(steps/3), for the price of one more forward solve per gradient (each state
// segment is re-solved once as the backward pass moves through it).
#include <Eigen/Dense>
#include <functional>
#include <map>
#include <vector>

#include "scoleid/identify/time/second_order_solver.h"
#include "scoleid/identify/time/trajectory.h"

namespace scoleid::identify {

struct Checkpoint {
  double t = 0.0, origin = 0.0, h = 0.0;
  Eigen::VectorXd x, v, a;
};

// Keeps a checkpoint at the first point and then at every `spacing`-th resumable point of column 0.
class CheckpointRecorder {
public:
  CheckpointRecorder(int n, std::size_t spacing) : n_(n), spacing_(spacing < 1 ? 1 : spacing) {}
  void operator()(const SecondOrderSolver::Point& pt);
  std::vector<Checkpoint>& checkpoints() { return ckpts_; }

private:
  int n_;
  std::size_t spacing_, since_ = 0;
  std::vector<Checkpoint> ckpts_;
};

// Collects streamed points into windows of at most `points` points and hands each window to
// `visit`; consecutive windows share their boundary point, and a breakpoint's two limits always stay
// in one window. finish() hands over the last window. A window holds the first `columns` columns of
// each point stacked (dimension columns · n: the state, then its tangents); a point with fewer
// columns throws std::logic_error.
class WindowedSink {
public:
  using Visit = std::function<void(const Trajectory&)>;
  WindowedSink(int n, std::size_t points, Visit visit, int columns = 1);
  void operator()(const SecondOrderSolver::Point& pt);
  void finish();

private:
  int n_, columns_;
  std::size_t points_;
  Visit visit_;
  Trajectory window_;
};

// Streams a solve over [t0, t1] and calls at(k, x, v) for every times[k] (ascending), x and v
// interpolated as Trajectory::eval would on the whole run (right limits at breakpoints, clamped to
// the run), holding `points` recorded points at a time instead of the whole solution.
using SampleVisit = std::function<void(std::size_t k, const Eigen::VectorXd& x, const Eigen::VectorXd& v)>;
void sample_streamed(const SecondOrderSolver& solver, double t0, double t1, const SecondOrderSolver::Forcing& forcing,
                     const std::vector<double>& breakpoints, const std::vector<double>& times, const SampleVisit& at,
                     SolverSummary* summary = nullptr, std::size_t points = 256,
                     const SecondOrderSolver::InitialState* initial = nullptr);

// The state between checkpoints, re-solved on demand: cover(ta, tb) makes the segments that hold
// [ta, tb] available, keeping only those (a backward pass moving to earlier windows then re-solves
// each segment once), and eval/times_in read them.
class CheckpointedState {
public:
  CheckpointedState(const SecondOrderSolver& solver, const SecondOrderSolver::Forcing& forcing,
                    std::vector<double> breakpoints, double t_end, std::vector<Checkpoint> checkpoints);
  void cover(double ta, double tb);
  // x(t), v(t), a(t) from the covered segment holding t (t within the last cover()).
  void eval(double t, double* x, double* v, double* a = nullptr) const;
  // The recorded times within [ta, tb] of the covered segments.
  void times_in(double ta, double tb, std::vector<double>& out) const;
  long resolves() const { return resolves_; }
  const SolverSummary& summary() const { return summary_; }

private:
  Trajectory solve_segment(std::size_t c);
  const SecondOrderSolver& solver_;
  const SecondOrderSolver::Forcing& forcing_;
  std::vector<double> breakpoints_;
  double t_end_;
  std::vector<Checkpoint> ckpts_;
  std::map<std::size_t, Trajectory> segments_;  // segment c: checkpoint c to checkpoint c + 1
  long resolves_ = 0;
  SolverSummary summary_;
};

}  // namespace scoleid::identify
