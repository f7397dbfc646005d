#pragma once
// Several experiments, one parameter vector (docs/theory.md §6.5):
//
//   J(q) = Σ_e J_e(q),   ∇J = Σ_e ∇J_e,   H_GN = Σ_e H_e,   H v = Σ_e H_e v
//
// each J_e a misfit of its own (a time-domain run with its inputs, sensors and data — one state
// solve forward and one costate solve backward per run for the gradient — or measured modes).
// The experiments are independent given q, so their evaluations run concurrently on a fixed
// number of threads; each result is stored in its experiment's slot and the sums are taken in
// experiment order afterwards, so the outcome is bit-identical to a serial evaluation whatever the
// number of threads or their timing. The worker threads live as long as the joint misfit: each
// keeps its experiments and their per-thread work arrays (time/trajectory.h) from one evaluation
// to the next, so an evaluation costs what the slowest thread's experiments cost, no more.
//
// Horizon. The records differ in length, so the joint horizon is a fraction s ∈ [0, 1] of every
// record: set_horizon(s) sets run e's horizon to t0_e + s (T_e − t0_e) (data_start() = 0,
// data_end() = 1). The joint misfit profile at s is the largest of the runs' profiles at the last
// of their samples at or before fraction s: the continuation (optimizers.h) lengthens the horizon
// only as far as every run's misfit allows (a run whose first sample lies beyond s counts with its
// first). Modal data have no horizon and always count whole.
#include <condition_variable>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "scoleid/identify/inverse/misfit.h"

namespace scoleid::identify {

struct JointMisfitOptions {
  int threads = 0;  // concurrent evaluations; 0 = the machine's hardware threads
};

class JointMisfit : public Misfit {
public:
  struct Component {
    std::string name;
    Misfit* misfit = nullptr;  // not owned
  };
  // Throws std::invalid_argument when there are no components or their sizes differ.
  explicit JointMisfit(std::vector<Component> components, JointMisfitOptions options = {});
  ~JointMisfit() override;
  JointMisfit(const JointMisfit&) = delete;
  JointMisfit& operator=(const JointMisfit&) = delete;

  int size() const override { return P_; }
  double horizon() const override { return s_; }
  double data_start() const override { return 0.0; }
  double data_end() const override { return 1.0; }
  void set_horizon(double s) override;
  long data_points() const override;

  double cost(const VectorXd& q) override;
  double cost_and_gradient(const VectorXd& q, VectorXd& gradient) override;
  double gauss_newton(const VectorXd& q, VectorXd& gradient, MatrixXd& H, MisfitProfile* profile = nullptr) override;
  MisfitProfile misfit_profile(const VectorXd& q) override;
  VectorXd gauss_newton_product(const VectorXd& q, const VectorXd& v) override;
  bool has_matrix_free_products() const override;

  int components() const { return static_cast<int>(parts_.size()); }
  const std::string& name(int e) const { return parts_[static_cast<std::size_t>(e)].name; }
  // Each experiment's J_e at the last evaluation (their sum is the last cost).
  const std::vector<double>& last_costs() const { return last_; }
  int threads() const { return threads_; }

private:
  // Runs f(e) for every experiment on the threads (experiment e on thread e mod threads, thread 0
  // the caller's); rethrows the first exception in experiment order after all have finished.
  void for_each(const std::function<void(int)>& f);
  void stripe(int k);
  void worker(int k);
  bool timed(int e) const;
  MisfitProfile combine(const std::vector<MisfitProfile>& profiles) const;

  std::vector<Component> parts_;
  int P_ = 0;
  int threads_ = 1;
  double s_ = 1.0;
  std::vector<double> last_;
  // The workers (threads 1 … threads − 1) and the job they wait for.
  std::vector<std::thread> pool_;
  std::mutex m_;
  std::condition_variable start_, done_;
  const std::function<void(int)>* job_ = nullptr;
  long generation_ = 0;
  int pending_ = 0;
  bool stop_ = false;
  std::vector<std::exception_ptr> errors_;
};

}  // namespace scoleid::identify
