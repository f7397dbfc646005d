#include "scoleid/identify/time/nonlinear_forward.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "scoleid/identify/time/esdirk_stepper.h"
#include "scoleid/io/interrupt.h"

namespace scoleid::identify {

namespace {

constexpr double kRefreshContraction = 0.3;
constexpr int kMaxNewton = 6;
// The Newton matrix is refactorised (same Jacobian) when the step changes by more than this.
constexpr double kRefactorStep = 0.05;
// A component's scale never counts below this (states in ft, rad, ft/s, rad/s): a component that
// is zero to rounding converges with any correction below 1e-6 times the tolerance.
constexpr double kAbsoluteFloor = 1e-6;

class Stepper {
public:
  Stepper(const ScoleNonlinear::Dynamics& dyn, const std::vector<io::Signal>& signals, double newton_tol,
          NonlinearForwardSummary& sum)
      : dyn_(dyn), signals_(signals), tol_(newton_tol), sum_(sum), tab_(nonlinear_table()) {
    if (tab_.stages < 2 || !tab_.explicit_first_stage() || !tab_.stiffly_accurate())
      throw std::logic_error("nonlinear forward: the table must have an explicit first stage and be stiffly accurate");
    gamma_ = tab_.a(1, 1);
    for (int i = 1; i < tab_.stages; ++i)
      if (std::abs(tab_.a(i, i) - gamma_) > 1e-15) throw std::logic_error("nonlinear forward: unequal diagonal");
    n_ = dyn.model().state_size();
    scale_ = VectorXd::Constant(n_, 1e-300);
  }

  VectorXd inputs(double t) const {
    VectorXd in(static_cast<Eigen::Index>(signals_.size()));
    for (std::size_t i = 0; i < signals_.size(); ++i) in[static_cast<Eigen::Index>(i)] = signals_[i](t);
    return in;
  }
  // f(t, y) with the inputs evaluated at t (already placed inside the step's interval).
  VectorXd f(double t, const VectorXd& y) {
    VectorXd d(n_);
    dyn_.derivative(y.data(), inputs(t), d.data());
    ++sum_.rhs_evaluations;
    return d;
  }

  // One step from (t, y) to t_end = t + h (given, so that it lands on the grid point exactly);
  // F0 = f at the step's start (right limit). The inputs are evaluated strictly inside the step:
  // a stage at either end sees the neighbouring representable time, i.e. the right limit at the
  // start and the left limit at the end. With `rec`, the stages are recorded.
  VectorXd step(double t, double t_end, const VectorXd& y, const VectorXd& F0, NonlinearStep* rec = nullptr) {
    scale_ = scale_.cwiseMax(y.cwiseAbs());
    const double h = t_end - t;
    const int s = tab_.stages;
    std::vector<VectorXd> F(static_cast<std::size_t>(s));
    F[0] = F0;
    const double lo = std::nextafter(t, t_end), hi = std::nextafter(t_end, t);
    VectorXd Y = y;
    for (int i = 1; i < s; ++i) {
      VectorXd z = y;
      for (int j = 0; j < i; ++j) z += h * tab_.a(i, j) * F[static_cast<std::size_t>(j)];
      const double ti = std::clamp(t + tab_.c[static_cast<std::size_t>(i)] * h, lo, hi);
      // Predictor: the stage equation with the previous stage's derivative, z_i + hγ F_{i−1}.
      const VectorXd start = z + h * gamma_ * F[static_cast<std::size_t>(i - 1)];
      bool done = false;
      for (int attempt = 0; attempt < 3 && !done; ++attempt) {
        if (!factor_) refresh(ti, start, h);
        else if (std::abs(h / h_ - 1.0) > kRefactorStep) factor(h);
        Y = start;
        VectorXd fY = f(ti, Y);
        double prev = std::numeric_limits<double>::infinity();
        for (int k = 0; k < kMaxNewton; ++k) {
          const VectorXd G = Y - h * gamma_ * fY - z;
          const VectorXd dY = lu_.solve(-G);
          Y += dY;
          ++sum_.newton_iterations;
          fY = f(ti, Y);
          const double size = (dY.cwiseAbs().array() / (Y.cwiseAbs() + scale_).array().max(kAbsoluteFloor)).maxCoeff();
          if (size <= tol_) {
            done = true;
            break;
          }
          if (k > 0 && size > kRefreshContraction * prev) break;
          prev = size;
        }
        // A fresh Jacobian where the iteration started (the failed iterate may not be finite).
        if (!done) refresh(ti, Y.allFinite() ? Y : start, h);
        else F[static_cast<std::size_t>(i)] = fY;
      }
      if (done && rec) {
        if (i == 1) rec->Y.assign(1, y);
        rec->Y.push_back(Y);
      }
      if (!done)
        throw std::runtime_error("nonlinear forward: Newton's iteration does not converge at t = " + std::to_string(ti) +
                                 " with step " + std::to_string(h) + " (a fresh Jacobian did not help)");
    }
    ++sum_.steps;
    last_F_ = F[static_cast<std::size_t>(s - 1)];
    if (rec) {
      rec->t = t;
      rec->h = h;
      rec->F = F;
      rec->inputs.clear();
      for (int i = 0; i < s; ++i)
        rec->inputs.push_back(inputs(std::clamp(t + tab_.c[static_cast<std::size_t>(i)] * h, lo, hi)));
    }
    return Y;  // stiffly accurate: y_{n+1} is the last stage
  }
  const VectorXd& last_derivative() const { return last_F_; }

private:
  void refresh(double t, const VectorXd& y, double h) {
    J_ = nonlinear_jacobian(dyn_, y, inputs(t), scale_);
    sum_.rhs_evaluations += n_ + 1;
    ++sum_.jacobian_evaluations;
    factor(h);
  }
  void factor(double h) {
    lu_.compute(MatrixXd::Identity(n_, n_) - h * gamma_ * J_);
    factor_ = true;
    h_ = h;
  }

  const ScoleNonlinear::Dynamics& dyn_;
  const std::vector<io::Signal>& signals_;
  double tol_;
  NonlinearForwardSummary& sum_;
  const ButcherTable& tab_;
  double gamma_ = 0.0, h_ = 0.0;
  int n_ = 0;
  bool factor_ = false;
  MatrixXd J_;
  Eigen::PartialPivLU<MatrixXd> lu_;
  VectorXd scale_, last_F_;
};

}  // namespace

const ButcherTable& nonlinear_table() {
  static const ButcherTable t = ButcherTable::arkode_dirk();
  return t;
}

MatrixXd nonlinear_jacobian(const ScoleNonlinear::Dynamics& dyn, const VectorXd& y, const VectorXd& inputs,
                            const VectorXd& scale) {
  const int n = static_cast<int>(y.size());
  VectorXd f0(n), fp(n);
  dyn.derivative(y.data(), inputs, f0.data());
  MatrixXd J(n, n);
  VectorXd yp = y;
  for (int j = 0; j < n; ++j) {
    const double d = 1e-7 * std::max(std::abs(y[j]), std::max(scale[j], 1e-6));
    yp[j] = y[j] + d;
    dyn.derivative(yp.data(), inputs, fp.data());
    J.col(j) = (fp - f0) / d;
    yp[j] = y[j];
  }
  return J;
}

bool NonlinearForwardOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) { if (why) *why = m; return false; };
  if (!(max_step >= 0 && std::isfinite(max_step))) return fail("max_step must be >= 0 (0 = a quarter of the sampling)");
  if (!(newton_tol > 0 && newton_tol < 1e-2)) return fail("newton_tol must lie in (0, 1e-2)");
  return true;
}

NonlinearResponse simulate_nonlinear(const ScoleNonlinear::Dynamics& dynamics, const std::vector<io::Signal>& signals,
                                     const std::vector<double>& times, const NonlinearForwardOptions& options,
                                     const VectorXd& y0, bool keep_steps) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("simulate_nonlinear: " + why);
  if (times.size() < 2) throw std::invalid_argument("simulate_nonlinear: at least two sample times are needed");
  for (std::size_t k = 1; k < times.size(); ++k)
    if (!(times[k] > times[k - 1])) throw std::invalid_argument("simulate_nonlinear: sample times must increase");
  if (static_cast<int>(signals.size()) != dynamics.model().inputs())
    throw std::invalid_argument("simulate_nonlinear: one signal per input is needed");
  const int N = dynamics.model().state_size();
  if (y0.size() != 0 && y0.size() != N) throw std::invalid_argument("simulate_nonlinear: initial state of the wrong size");
  const auto clock0 = std::chrono::steady_clock::now();
  const double h_max = options.max_step > 0 ? options.max_step : (times[1] - times[0]) / 4.0;

  // The grid: sample times and breakpoints.
  std::vector<double> grid = times;
  for (const auto& s : signals)
    for (double b : s.breakpoints())
      if (b > times.front() && b < times.back()) grid.push_back(b);
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end(), [](double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(a)); }), grid.end());
  std::vector<char> is_break(grid.size(), 0);
  for (const auto& s : signals)
    for (double b : s.breakpoints()) {
      // The grid point that stands for b (sorted grid; a table signal has a breakpoint per sample).
      const double tol = 1e-12 * std::max(1.0, std::abs(b));
      const auto it = std::lower_bound(grid.begin(), grid.end(), b - tol);
      if (it != grid.end() && std::abs(*it - b) <= tol) is_break[static_cast<std::size_t>(it - grid.begin())] = 1;
    }

  NonlinearResponse r;
  r.t = times;
  r.outputs.resize(static_cast<Eigen::Index>(times.size()), dynamics.model().sensors());
  Stepper st(dynamics, signals, options.newton_tol, r.summary);
  VectorXd y = y0.size() ? y0 : VectorXd(VectorXd::Zero(N));
  auto record = [&](std::size_t k, double t_eval, const VectorXd& yk) {
    VectorXd in(static_cast<Eigen::Index>(signals.size()));
    for (std::size_t i = 0; i < signals.size(); ++i) in[static_cast<Eigen::Index>(i)] = signals[i](t_eval);
    r.sample_inputs.push_back(in);
    VectorXd yd(N), udot;
    dynamics.derivative(yk.data(), in, yd.data(), &udot);
    r.outputs.row(static_cast<Eigen::Index>(k)) = dynamics.outputs(yk.data(), udot).transpose();
    r.states.push_back(yk);
  };
  std::size_t next_sample = 0;
  const double t0 = grid.front();
  record(next_sample++, t0, y);
  VectorXd F;
  bool fresh = true;  // F must be evaluated (start, or after a breakpoint)
  for (std::size_t g = 0; g + 1 < grid.size(); ++g) {
    io::check_interrupt();  // a signal ends a long solve between samples, not after it
    const double a = grid[g], b = grid[g + 1];
    const int m = std::max(1, static_cast<int>(std::ceil((b - a) / h_max - 1e-9)));
    const double h = (b - a) / m;
    for (int k = 0; k < m; ++k) {
      const double t = a + k * h, t_end = k + 1 == m ? b : a + (k + 1) * h;
      if (fresh) F = st.f(std::nextafter(t, t_end), y);
      NonlinearStep* rec = nullptr;
      if (keep_steps) {
        r.steps.emplace_back();
        rec = &r.steps.back();
      }
      y = st.step(t, t_end, y, F, rec);
      F = st.last_derivative();
      fresh = false;
    }
    if (is_break[g + 1]) fresh = true;
    if (next_sample < times.size() && std::abs(times[next_sample] - b) <= 1e-12 * std::max(1.0, std::abs(b))) {
      if (keep_steps) r.steps.back().sample = static_cast<int>(next_sample);
      record(next_sample++, b, y);
    }
  }
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock0).count();
  return r;
}

}  // namespace scoleid::identify
