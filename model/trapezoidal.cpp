#include "scoleid/model/trapezoidal.h"

#include <algorithm>
#include <cstdio>
#include <utility>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "implicit_support.h"

namespace scoleid::model {

using namespace SimTK;
using detail::str;
using detail::view;

TrapezoidalIntegrator::TrapezoidalIntegrator(const MultibodySystem& system, const State& initial,
                                             const TrapezoidalOptions& options)
    : system_(system), matter_(system.getMatterSubsystem()), options_(options), state_(initial), trial_(initial) {
  std::string why;
  if (!options_.IsValid(&why)) throw std::invalid_argument("TrapezoidalIntegrator: " + why);
  detail::require_unconstrained(system_, initial, "TrapezoidalIntegrator");
  realize(state_);
  q_initial_ = state_.getQ();
  refresh_jacobian(state_);
  summary_.lowest_omega = options_.reference_omega > 0 ? options_.reference_omega
                                                       : detail::default_state_omega(system_, &summary_.realizations);
  summary_.max_step = implicit_step_bound(options_, summary_.lowest_omega, std::cbrt(12.0 * options_.accuracy));
}

void TrapezoidalIntegrator::realize(State& s) const { system_.realize(s, Stage::Acceleration); }

void TrapezoidalIntegrator::refresh_jacobian(const State& at) {
  detail::acceleration_jacobian(system_, at, A_, B_);
  summary_.realizations += 4 * at.getNU();
  ++summary_.jacobians;
  factors_.clear();
}

const Eigen::PartialPivLU<Eigen::MatrixXd>& TrapezoidalIntegrator::newton_matrix(double h) {
  const long long key = std::llround(h * 1e12);
  auto it = factors_.find(key);
  if (it != factors_.end()) return it->second;
  const Eigen::Index nu = A_.rows();
  const Eigen::MatrixXd W = Eigen::MatrixXd::Identity(nu, nu) - 0.5 * h * B_ - 0.25 * h * h * A_;
  ++summary_.factorizations;
  return factors_.emplace(key, Eigen::PartialPivLU<Eigen::MatrixXd>(W)).first->second;
}

void TrapezoidalIntegrator::advance_to(double t_end, bool left_limit) {
  const double t0 = time();
  if (!(t_end > t0)) return;
  const double span = t_end - t0;
  const long long n = equal_steps(span, summary_.max_step);
  const double h = span / static_cast<double>(n);
  for (long long i = 1; i <= n; ++i) {
    const double t1 = i == n ? t_end : t0 + static_cast<double>(i) * h;
    step(t1 - time(), left_limit && i == n);
  }
}

void TrapezoidalIntegrator::step(double h, bool left_limit) {
  const double t1 = state_.getTime() + h;
  // Input's left limit at a breakpoint: the step's end is evaluated a hair before it.
  const double t_eval = left_limit ? t1 - 1e-9 * h : t1;
  const int nu = state_.getNU(), nq = state_.getNQ();
  const Eigen::VectorXd q0 = view(state_.getQ()), u0 = view(state_.getU());
  const Eigen::VectorXd qd0 = view(state_.getQDot()), a0 = view(state_.getUDot());
  const auto qi = view(q_initial_);
  // Corrections below 1e-13 of the state scale are round-off in the residual itself.
  const double tol = std::max(options_.newton_fraction * options_.accuracy, 1e-13);
  const double tiny = std::numeric_limits<double>::min();

  const State* cur = &state_;
  double prev = std::numeric_limits<double>::infinity();
  int since_refresh = 0, refreshes = 0;
  Vector gq(nq), gd(nu), dd_s(nu), dq(nq);
  Eigen::VectorXd rhs(nu), du(nu), dd(nu), q_next(nq), u_next(nu);
  for (int k = 0;; ++k) {
    const auto q = view(cur->getQ());
    const auto u = view(cur->getU());
    Eigen::Map<Eigen::VectorXd>(&gq[0], nq) = q - q0 - 0.5 * h * (qd0 + view(cur->getQDot()));
    matter_.multiplyByNInv(*cur, false, gq, gd);
    const auto gde = view(gd);
    rhs.noalias() = -0.5 * h * (A_ * gde);
    rhs -= u - u0 - 0.5 * h * (a0 + view(cur->getUDot()));
    du = newton_matrix(h).solve(rhs);
    dd = -gde + 0.5 * h * du;

    const double us = std::max(u_scale_, u.cwiseAbs().maxCoeff());
    const double ds = std::max(d_scale_, (q - qi).cwiseAbs().maxCoeff());
    const double norm = std::max(du.cwiseAbs().maxCoeff() / std::max(us, tiny), dd.cwiseAbs().maxCoeff() / std::max(ds, tiny));
    if (k >= 1 && norm <= tol) break;   // *cur solves the step to within the tolerance
    if (k >= 1) {
      ++summary_.newton_iterations;
      ++since_refresh;
      const bool slow = since_refresh >= 2 && norm > options_.refresh_contraction * prev;
      if (slow || since_refresh >= options_.max_newton_iterations) {
        if (refreshes == 2)
          throw std::runtime_error("trapezoidal rule: Newton iteration does not converge at t = " + str(t1) +
                                   " (correction " + str(norm) + " of the state scale, step " + str(h) + " s)");
        refresh_jacobian(*cur);
        ++refreshes;
        since_refresh = 0;
        prev = std::numeric_limits<double>::infinity();
        --k;   // recompute the correction at *cur with the new Newton matrix
        continue;
      }
    }
    prev = norm;
    Eigen::Map<Eigen::VectorXd>(&dd_s[0], nu) = dd;
    matter_.multiplyByN(*cur, false, dd_s, dq);
    q_next = q + view(dq);
    u_next = u + du;
    Eigen::Map<Eigen::VectorXd>(&trial_.updQ()[0], nq) = q_next;
    Eigen::Map<Eigen::VectorXd>(&trial_.updU()[0], nu) = u_next;
    trial_.setTime(t_eval);
    realize(trial_);
    ++summary_.realizations;
    cur = &trial_;
  }
  std::swap(state_, trial_);   // moves: the realized cache goes with the state
  if (left_limit) {
    state_.setTime(t1);
    realize(state_);
    ++summary_.realizations;
  }
  u_scale_ = std::max(u_scale_, view(state_.getU()).cwiseAbs().maxCoeff());
  d_scale_ = std::max(d_scale_, (view(state_.getQ()) - qi).cwiseAbs().maxCoeff());
  summary_.largest_step = std::max(summary_.largest_step, h);
  ++summary_.steps;
}

}  // namespace scoleid::model
