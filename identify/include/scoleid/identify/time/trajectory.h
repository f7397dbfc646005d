#pragma once
// A solution recorded at the integrator's own steps: t_k, x_k, v_k = ẋ_k, a_k = ẍ_k.
// Between steps x is the cubic Hermite interpolant of (x, v) and v that of (v, a), so the
// interpolation error is O(h⁴) in the integrator's step h, below the integrator's own error
// at the tolerances used. A time may appear twice (left and right limits at a breakpoint
// where the forcing, hence a, jumps).
//
// Storage: an identification records several trajectories of a few MB per cost evaluation.
// Their arrays are recycled through a small per-thread pool (reserve takes, the destructor
// returns), so repeated solves reuse memory the process has already touched instead of mapping
// and faulting in fresh pages each time.
#include <Eigen/Dense>
#include <vector>

namespace scoleid::identify {

class Trajectory {
public:
  explicit Trajectory(int n = 0) : n_(n) {}
  ~Trajectory();
  Trajectory(const Trajectory&) = default;
  Trajectory& operator=(const Trajectory&) = default;
  Trajectory(Trajectory&&) noexcept = default;
  Trajectory& operator=(Trajectory&&) noexcept = default;
  int dim() const { return n_; }
  std::size_t size() const { return t_.size(); }
  const std::vector<double>& times() const { return t_; }
  double t_begin() const { return t_.front(); }
  double t_end() const { return t_.back(); }

  void push(double t, const double* x, const double* v, const double* a);
  // Room for `points` recorded points without reallocation (from the pool when it can).
  void reserve(std::size_t points);
  // x(t), v(t) (and a(t), linear in between) by Hermite interpolation; t is clamped to the range.
  // v (like a) may be null when only x is wanted.
  // When t coincides with a duplicated breakpoint time, `right` selects the right limit.
  void eval(double t, double* x, double* v, double* a = nullptr, bool right = true) const;
  Eigen::Map<const Eigen::VectorXd> x(std::size_t k) const { return {X_.data() + k * n_, n_}; }
  Eigen::Map<const Eigen::VectorXd> v(std::size_t k) const { return {V_.data() + k * n_, n_}; }
  Eigen::Map<const Eigen::VectorXd> a(std::size_t k) const { return {A_.data() + k * n_, n_}; }

private:
  std::size_t locate(double t, bool right) const;
  int n_;
  std::vector<double> t_, X_, V_, A_;
  mutable std::size_t hint_ = 0;
};

}  // namespace scoleid::identify
