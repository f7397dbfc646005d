#include "scoleid/model/gauss_legendre.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "implicit_support.h"

namespace scoleid::model {

using namespace SimTK;
using detail::str;
using detail::view;
using detail::view_mut;

namespace {
constexpr int kMaxSplits = 6;   // a failing step is halved at most this many times
// The two-stage Gauss–Legendre tableau.
const double kR3 = std::sqrt(3.0);
const double kC[2] = {0.5 - kR3 / 6.0, 0.5 + kR3 / 6.0};
const double kA[2][2] = {{0.25, 0.25 - kR3 / 6.0}, {0.25 + kR3 / 6.0, 0.25}};
const double kD[2] = {-kR3, kR3};   // b^T a^-1: y1 = y0 + sum_i d_i Z_i
}  // namespace

bool GaussLegendreOptions::IsValid(std::string* why) const {
  if (!ImplicitStepOptions::IsValid(why)) return false;
  auto bad = [why](const std::string& m) { if (why) *why = m; return false; };
  if (output_stage != Stage::Velocity && output_stage != Stage::Acceleration)
    return bad("output_stage must be Velocity or Acceleration");
  return true;
}

GaussLegendreIntegrator::GaussLegendreIntegrator(const MultibodySystem& system, const State& initial,
                                                 const GaussLegendreOptions& options)
    : system_(system), matter_(system.getMatterSubsystem()), options_(options), state_(initial),
      stage_{initial, initial} {
  std::string why;
  if (!options_.IsValid(&why)) throw std::invalid_argument("GaussLegendreIntegrator: " + why);
  detail::require_unconstrained(system_, initial, "GaussLegendreIntegrator");
  realize(state_);
  q_initial_ = state_.getQ();
  refresh_jacobian(state_);
  summary_.lowest_omega = options_.reference_omega > 0 ? options_.reference_omega
                                                       : detail::default_state_omega(system_, &summary_.realizations);
  summary_.max_step = implicit_step_bound(options_, summary_.lowest_omega, std::pow(720.0 * options_.accuracy, 0.2));
  for (int i = 0; i < 2; ++i) {
    zq_[i].setZero(state_.getNQ());
    zu_[i].setZero(state_.getNU());
  }
}

void GaussLegendreIntegrator::realize(State& s) const { system_.realize(s, Stage::Acceleration); }

void GaussLegendreIntegrator::refresh_jacobian(const State& at) {
  detail::acceleration_jacobian(system_, at, A_, B_);
  summary_.realizations += 4 * at.getNU();
  ++summary_.jacobians;
  factors_.clear();
}

const Eigen::PartialPivLU<Eigen::MatrixXd>& GaussLegendreIntegrator::newton_matrix(double h) {
  const long long key = std::llround(h * 1e12);
  auto it = factors_.find(key);
  if (it != factors_.end()) return it->second;
  const Eigen::Index nu = A_.rows();
  // I - h a (x) B - h^2 a^2 (x) A
  double a2[2][2];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) a2[i][j] = kA[i][0] * kA[0][j] + kA[i][1] * kA[1][j];
  Eigen::MatrixXd W(2 * nu, 2 * nu);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      W.block(i * nu, j * nu, nu, nu) = -h * kA[i][j] * B_ - h * h * a2[i][j] * A_;
  W.diagonal().array() += 1.0;
  ++summary_.factorizations;
  return factors_.emplace(key, Eigen::PartialPivLU<Eigen::MatrixXd>(W)).first->second;
}

void GaussLegendreIntegrator::advance_to(double t_end, bool breakpoint) {
  const double t0 = time();
  if (!(t_end > t0)) return;
  const double span = t_end - t0;
  const long long n = equal_steps(span, summary_.max_step);
  const double h = span / static_cast<double>(n);
  for (long long i = 1; i <= n; ++i) {
    const double t1 = i == n ? t_end : t0 + static_cast<double>(i) * h;
    step_or_split(t1 - time(), 0);
  }
  if (breakpoint) h_prev_ = 0.0;   // the inputs jump: do not extrapolate across
}

// Stage increments to start from: the last step's collocation polynomial (through 0, Z_1, Z_2 at
// theta = 0, c_1, c_2 of that step) extrapolated to this step's stage times, less its value at
// the step's end; Euler increments c_i h y0' without a last step.
void GaussLegendreIntegrator::predict(double h) {
  if (h_prev_ > 0) {
    auto L = [](double th, int j) {   // Lagrange basis on {0, c1, c2}, the node j (0 or 1 for c1, c2)
      const double cj = kC[j], ck = kC[1 - j];
      return th * (th - ck) / (cj * (cj - ck));
    };
    const Eigen::VectorXd zq1 = L(1.0, 0) * zq_[0] + L(1.0, 1) * zq_[1];
    const Eigen::VectorXd zu1 = L(1.0, 0) * zu_[0] + L(1.0, 1) * zu_[1];
    Eigen::VectorXd nq[2], nu[2];
    for (int i = 0; i < 2; ++i) {
      const double th = 1.0 + kC[i] * h / h_prev_;
      nq[i] = L(th, 0) * zq_[0] + L(th, 1) * zq_[1] - zq1;
      nu[i] = L(th, 0) * zu_[0] + L(th, 1) * zu_[1] - zu1;
    }
    for (int i = 0; i < 2; ++i) {
      zq_[i] = std::move(nq[i]);
      zu_[i] = std::move(nu[i]);
    }
  } else {
    if (state_.getSystemStage() < Stage::Acceleration) {   // y0' (the step ends are realized to output_stage)
      realize(state_);
      ++summary_.realizations;
    }
    for (int i = 0; i < 2; ++i) {
      zq_[i] = kC[i] * h * view(state_.getQDot());
      zu_[i] = kC[i] * h * view(state_.getUDot());
    }
  }
}

// A step whose Newton iteration fails is taken as two halves (each split again if it fails, down
// to 1/64 of the step); the run fails only below that.
void GaussLegendreIntegrator::step_or_split(double h, int depth) {
  std::string why;
  if (step(h, &why)) return;
  if (depth == kMaxSplits) throw std::runtime_error(why);
  ++summary_.split_steps;
  h_prev_ = 0.0;   // start the halves from Euler increments
  const double t1 = time() + h;
  step_or_split(0.5 * h, depth + 1);
  step_or_split(t1 - time(), depth + 1);
}

bool GaussLegendreIntegrator::step(double h, std::string* why) {
  const double t0 = state_.getTime(), t1 = t0 + h;
  const int nu = state_.getNU(), nq = state_.getNQ();
  const Eigen::VectorXd q0 = view(state_.getQ()), u0 = view(state_.getU());
  const auto qi = view(q_initial_);
  // Corrections below 1e-13 of the state scale are round-off in the residual itself.
  const double tol = std::max(options_.newton_fraction * options_.accuracy, 1e-13);
  const double tiny = std::numeric_limits<double>::min();

  predict(h);
  // eta: the error a correction leaves, per unit of its size, from this step's measured contraction.
  double eta = std::numeric_limits<double>::infinity();
  double prev = std::numeric_limits<double>::infinity();
  int since_refresh = 0, refreshes = 0;
  Vector gq(nq), gd(nu), dd_s(nu), dq(nq);
  Eigen::VectorXd g(2 * nu), Ag(2 * nu), rhs(2 * nu), du(2 * nu), dqi(nq), Gq_all[2], Ndu[2];
  for (;;) {
    for (int i = 0; i < 2; ++i) {
      State& s = stage_[i];
      view_mut(s.updQ()) = q0 + zq_[i];
      view_mut(s.updU()) = u0 + zu_[i];
      s.setTime(t0 + kC[i] * h);
      ++summary_.realizations;
      try {
        realize(s);
      } catch (const std::exception& e) {   // an iterate Simbody cannot evaluate (NaN inertia, ...)
        *why = "Gauss-Legendre rule: a Newton iterate cannot be evaluated at t = " + str(t0 + kC[i] * h) + " (step " +
               str(h) + " s): " + e.what();
        return false;
      }
    }
    for (int i = 0; i < 2; ++i) {
      Eigen::VectorXd Gq = zq_[i], Gu = zu_[i];
      for (int j = 0; j < 2; ++j) {
        Gq -= h * kA[i][j] * view(stage_[j].getQDot());
        Gu -= h * kA[i][j] * view(stage_[j].getUDot());
      }
      view_mut(gq) = Gq;
      Gq_all[i] = std::move(Gq);
      matter_.multiplyByNInv(stage_[i], false, gq, gd);
      g.segment(i * nu, nu) = view(gd);
      Ag.segment(i * nu, nu).noalias() = A_ * view(gd);
      rhs.segment(i * nu, nu) = -Gu;
    }
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) rhs.segment(i * nu, nu) -= h * kA[i][j] * Ag.segment(j * nu, nu);
    du = newton_matrix(h).solve(rhs);
    ++summary_.newton_iterations;
    // Position corrections in q itself: delta q_i = -G_q,i + h sum_j a_ij N(Q_j) du_j. Going
    // through N_i delta_i instead would leave the part of G_q,i outside N_i's range unsolved (a
    // quaternion's radial part), and that error is first order in h.
    for (int j = 0; j < 2; ++j) {
      view_mut(dd_s) = du.segment(j * nu, nu);
      matter_.multiplyByN(stage_[j], false, dd_s, dq);
      Ndu[j] = view(dq);
    }
    double nu_max = 0.0, nd_max = 0.0, us = std::max(u_scale_, u0.cwiseAbs().maxCoeff()), ds = d_scale_;
    for (int i = 0; i < 2; ++i) {
      dqi = -Gq_all[i];
      for (int j = 0; j < 2; ++j) dqi += h * kA[i][j] * Ndu[j];
      zq_[i] += dqi;
      zu_[i] += du.segment(i * nu, nu);
      nu_max = std::max(nu_max, du.segment(i * nu, nu).cwiseAbs().maxCoeff());
      nd_max = std::max(nd_max, dqi.cwiseAbs().maxCoeff());
      us = std::max(us, (u0 + zu_[i]).cwiseAbs().maxCoeff());
      ds = std::max(ds, (q0 + zq_[i] - qi).cwiseAbs().maxCoeff());
    }
    const double norm = std::max(nu_max / std::max(us, tiny), nd_max / std::max(ds, tiny));
    if (!std::isfinite(norm)) {
      *why = "Gauss-Legendre rule: Newton correction is not finite at t = " + str(t1) + " (step " + str(h) + " s)";
      return false;
    }
    if (prev < std::numeric_limits<double>::infinity()) {
      const double theta = norm / prev;
      eta = theta < 1.0 ? theta / (1.0 - theta) : std::numeric_limits<double>::infinity();
      ++since_refresh;
      // Slow: refresh the Jacobian (twice per step at most); after that, go on while it contracts.
      const bool slow = norm > tol && (theta > options_.refresh_contraction || since_refresh >= options_.max_newton_iterations);
      if (slow && refreshes < 2) {
        refresh_jacobian(state_);
        ++refreshes;
        since_refresh = 0;
        prev = std::numeric_limits<double>::infinity();
        eta = std::numeric_limits<double>::infinity();
        continue;
      }
      if (slow && (theta >= 1.0 || since_refresh >= 4 * options_.max_newton_iterations)) {
        // Corrections that no longer shrink within a hundred times the tolerance are the
        // residual's round-off (the Newton matrix's condition grows as (h omega_max)^2): the step
        // is accepted and counted.
        if (norm <= 100.0 * tol) {
          ++summary_.roundoff_limited_steps;
          summary_.largest_roundoff_correction = std::max(summary_.largest_roundoff_correction, norm);
          break;
        }
        *why = "Gauss-Legendre rule: Newton iteration does not converge at t = " + str(t1) + " (correction " +
               str(norm) + " of the state scale, step " + str(h) + " s; the trapezoidal rule's shorter steps may converge)";
        return false;
      }
    }
    // The stages solve the step to within the tolerance: the correction left is below it, or a
    // second correction already is.
    if (norm <= tol * 1e-3 || eta * norm <= tol || (prev < std::numeric_limits<double>::infinity() && norm <= tol)) break;
    prev = norm;
  }
  view_mut(state_.updQ()) = q0 + kD[0] * zq_[0] + kD[1] * zq_[1];
  view_mut(state_.updU()) = u0 + kD[0] * zu_[0] + kD[1] * zu_[1];
  state_.setTime(t1);
  ++summary_.realizations;
  try {
    system_.realize(state_, options_.output_stage);
  } catch (const std::exception& e) {   // the step's end cannot be evaluated: back to y0
    *why = "Gauss-Legendre rule: the step's end cannot be evaluated at t = " + str(t1) + " (step " + str(h) + " s): " + e.what();
    view_mut(state_.updQ()) = q0;
    view_mut(state_.updU()) = u0;
    state_.setTime(t0);
    system_.realize(state_, options_.output_stage);
    return false;
  }
  h_prev_ = h;
  u_scale_ = std::max(u_scale_, view(state_.getU()).cwiseAbs().maxCoeff());
  d_scale_ = std::max(d_scale_, (view(state_.getQ()) - qi).cwiseAbs().maxCoeff());
  summary_.largest_step = std::max(summary_.largest_step, h);
  ++summary_.steps;
  return true;
}

}  // namespace scoleid::model
