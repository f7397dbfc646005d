#include "scoleid/model/linearisation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace scoleid::model {

using namespace SimTK;

bool LinearisationOptions::IsValid(std::string* why) const {
  if (!(step > 0 && step < 1)) { if (why) *why = "step must be in (0, 1)"; return false; }
  if (!(zero_tolerance >= 0)) { if (why) *why = "zero_tolerance must be >= 0"; return false; }
  return true;
}

Eigen::VectorXd generalized_accelerations(const MultibodySystem& system, const State& state) {
  system.realize(state, Stage::Acceleration);
  const Vector& udot = state.getUDot();
  Eigen::VectorXd out(udot.size());
  for (int i = 0; i < udot.size(); ++i) out[i] = udot[i];
  return out;
}

namespace {
const SimbodyMatterSubsystem& matter_of(const MultibodySystem& system) { return system.getMatterSubsystem(); }

// q = q0 + N(q0) delta
void displace(const MultibodySystem& system, const State& base, const Vector& delta, State& out) {
  Vector dq;
  system.realize(base, Stage::Position);
  matter_of(system).multiplyByN(base, false, delta, dq);
  out.updQ() = base.getQ() + dq;
}
}  // namespace

Eigen::MatrixXd state_jacobian(const MultibodySystem& system, const State& eq, const LinearisationOptions& opt) {
  std::string why;
  if (!opt.IsValid(&why)) throw std::invalid_argument("state_jacobian: " + why);
  const int nu = eq.getNU();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * nu, 2 * nu);
  A.block(0, nu, nu, nu).setIdentity();
  State s = eq;
  const double h = opt.step;
  for (int j = 0; j < nu; ++j) {
    Vector delta(nu, 0.0);
    delta[j] = h;
    displace(system, eq, delta, s);
    const Eigen::VectorXd ap = generalized_accelerations(system, s);
    delta[j] = -h;
    displace(system, eq, delta, s);
    const Eigen::VectorXd am = generalized_accelerations(system, s);
    A.block(nu, j, nu, 1) = (ap - am) / (2 * h);
  }
  s.updQ() = eq.getQ();
  for (int j = 0; j < nu; ++j) {
    s.updU() = eq.getU();
    s.updU()[j] += h;
    const Eigen::VectorXd ap = generalized_accelerations(system, s);
    s.updU()[j] -= 2 * h;
    const Eigen::VectorXd am = generalized_accelerations(system, s);
    A.block(nu, nu + j, nu, 1) = (ap - am) / (2 * h);
  }
  return A;
}

std::vector<Mode> modes_of(const Eigen::MatrixXd& A, double zero_tolerance) {
  Eigen::EigenSolver<Eigen::MatrixXd> es(A, false);
  std::vector<Mode> modes;
  for (int i = 0; i < es.eigenvalues().size(); ++i) {
    const std::complex<double> l = es.eigenvalues()[i];
    const double w = std::abs(l);
    if (l.imag() <= 0.0 || w <= zero_tolerance) continue;
    modes.push_back({w / (2 * Pi), w, -l.real() / w});
  }
  std::sort(modes.begin(), modes.end(), [](const Mode& a, const Mode& b) { return a.omega < b.omega; });
  return modes;
}

std::vector<Mode> natural_modes(const MultibodySystem& system, const State& eq, const LinearisationOptions& opt) {
  return modes_of(state_jacobian(system, eq, opt), opt.zero_tolerance);
}

double solve_static_equilibrium(const MultibodySystem& system, State& state, const std::vector<int>& mob,
                                int max_iterations, double tolerance) {
  const int nu = state.getNU();
  const int m = static_cast<int>(mob.size());
  state.updU() = 0.0;
  auto residual = [&](const State& s) {
    const Eigen::VectorXd a = generalized_accelerations(system, s);
    Eigen::VectorXd r(m);
    for (int i = 0; i < m; ++i) r[i] = a[mob[static_cast<std::size_t>(i)]];
    return r;
  };
  Eigen::VectorXd r = residual(state);
  for (int it = 0; it < max_iterations && r.lpNorm<Eigen::Infinity>() > tolerance; ++it) {
    const double h = 1e-7;
    Eigen::MatrixXd J(m, m);
    State s = state;
    for (int j = 0; j < m; ++j) {
      Vector delta(nu, 0.0);
      delta[mob[static_cast<std::size_t>(j)]] = h;
      displace(system, state, delta, s);
      const Eigen::VectorXd rp = residual(s);
      delta[mob[static_cast<std::size_t>(j)]] = -h;
      displace(system, state, delta, s);
      J.col(j) = (rp - residual(s)) / (2 * h);
    }
    const Eigen::VectorXd step = J.partialPivLu().solve(-r);
    Vector delta(nu, 0.0);
    for (int j = 0; j < m; ++j) delta[mob[static_cast<std::size_t>(j)]] = step[j];
    State next = state;
    displace(system, state, delta, next);
    state = next;
    r = residual(state);
  }
  return r.lpNorm<Eigen::Infinity>();
}

}  // namespace scoleid::model
