#include "scoleid/model/linearisation.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "scoleid/io/interrupt.h"

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

// ∂value/∂δ_j at `base` by central differences: `value` of the state displaced by ±h along the
// generalized speed j (q = q0 + N(q0) δ, through `s`), (value₊ − value₋) / 2h.
Eigen::VectorXd central_difference(const MultibodySystem& system, const State& base, int j, double h, State& s,
                                   const std::function<Eigen::VectorXd(const State&)>& value) {
  Vector delta(base.getNU(), 0.0);
  delta[j] = h;
  displace(system, base, delta, s);
  const Eigen::VectorXd plus = value(s);
  delta[j] = -h;
  displace(system, base, delta, s);
  const Eigen::VectorXd minus = value(s);
  io::check_interrupt();
  return (plus - minus) / (2 * h);
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
  const auto accelerations = [&](const State& st) { return generalized_accelerations(system, st); };
  for (int j = 0; j < nu; ++j) A.block(nu, j, nu, 1) = central_difference(system, eq, j, h, s, accelerations);
  s.updQ() = eq.getQ();
  for (int j = 0; j < nu; ++j) {
    s.updU() = eq.getU();
    s.updU()[j] += h;
    const Eigen::VectorXd ap = generalized_accelerations(system, s);
    s.updU()[j] -= 2 * h;
    const Eigen::VectorXd am = generalized_accelerations(system, s);
    A.block(nu, nu + j, nu, 1) = (ap - am) / (2 * h);
    io::check_interrupt();
  }
  return A;
}

std::vector<Mode> modes_of(const Eigen::MatrixXd& A, double zero_tolerance) {
  // Rigid-body and constraint directions have |lambda| = 0 up to the round-off of the differenced
  // accelerations, about sqrt(eps max |du_dot/d delta|_jj); a fine chain's stiff joints make that
  // level grow with n (1.7e-3 rad/s for SCOLE at 160 segments), so the floor follows it.
  const int nu = static_cast<int>(A.rows()) / 2;
  double kmax = 0.0;
  for (int j = 0; j < nu; ++j) kmax = std::max(kmax, std::abs(A(nu + j, j)));
  const double floor = std::max(zero_tolerance, 30.0 * std::sqrt(std::numeric_limits<double>::epsilon() * kmax));
  const Eigen::VectorXcd lambda =
      io::interruptible([A]() -> Eigen::VectorXcd { return Eigen::EigenSolver<Eigen::MatrixXd>(A, false).eigenvalues(); });
  std::vector<Mode> modes;
  for (int i = 0; i < lambda.size(); ++i) {
    const std::complex<double> l = lambda[i];
    const double w = std::abs(l);
    if (l.imag() <= 0.0 || w <= floor) continue;
    modes.push_back({w / (2 * Pi), w, -l.real() / w});
  }
  std::sort(modes.begin(), modes.end(), [](const Mode& a, const Mode& b) { return a.omega < b.omega; });
  return modes;
}

std::vector<Mode> natural_modes(const MultibodySystem& system, const State& eq, const LinearisationOptions& opt) {
  return modes_of(state_jacobian(system, eq, opt), opt.zero_tolerance);
}

ModeShapes undamped_modes(const MultibodySystem& system, const State& eq, const OutputFunction& outputs,
                          const LinearisationOptions& opt) {
  std::string why;
  if (!opt.IsValid(&why)) throw std::invalid_argument("undamped_modes: " + why);
  const int nu = eq.getNU();
  State base = eq;
  base.updU() = 0.0;
  system.realize(base, Stage::Position);
  const Eigen::VectorXd y0 = outputs(base);
  const int ny = static_cast<int>(y0.size());
  Eigen::MatrixXd K(nu, nu), Cy(ny, nu);
  State s = base;
  const double h = opt.step;
  const auto accelerations_and_outputs = [&](const State& st) {
    Eigen::VectorXd v(nu + ny);
    v << generalized_accelerations(system, st), outputs(st);
    return v;
  };
  for (int j = 0; j < nu; ++j) {
    const Eigen::VectorXd d = central_difference(system, base, j, h, s, accelerations_and_outputs);
    K.col(j) = -d.head(nu);
    Cy.col(j) = d.tail(ny);
  }
  // Rigid-body and constraint directions have omega^2 = 0 up to the round-off of the differenced
  // accelerations, about eps * max K_ii (the largest terms cancel); 30 times that is the floor.
  double kmax = opt.zero_tolerance * opt.zero_tolerance;
  for (int j = 0; j < nu; ++j) kmax = std::max(kmax, std::abs(K(j, j)));
  const double floor = std::max(opt.zero_tolerance, 30.0 * std::sqrt(std::numeric_limits<double>::epsilon() * kmax));
  std::vector<std::pair<double, int>> order;
  Eigen::MatrixXd vectors;
  if (system.getMatterSubsystem().getNumConstraints() == 0) {
    // Unconstrained: M (du_dot/d delta) is minus the Hessian of the potential at the equilibrium,
    // symmetric, so the problem is the symmetric-definite K_s phi = omega^2 M phi (several times
    // faster than the general eigenproblem, and real by construction).
    Matrix Ms;
    system.getMatterSubsystem().calcM(base, Ms);
    Eigen::MatrixXd M(nu, nu);
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nu; ++j) M(i, j) = Ms(i, j);
    Eigen::MatrixXd Ks = M * K;
    Ks = 0.5 * (Ks + Ks.transpose()).eval();
    const auto es = io::interruptible([Ks, M] {
      return std::make_shared<Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd>>(
          Ks, M, Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
    });
    for (int i = 0; i < nu; ++i)
      if (es->eigenvalues()[i] > floor * floor) order.push_back({std::sqrt(es->eigenvalues()[i]), i});
    vectors = es->eigenvectors();
  } else {
    const auto solver = io::interruptible([K] { return std::make_shared<Eigen::EigenSolver<Eigen::MatrixXd>>(K, true); });
    const Eigen::EigenSolver<Eigen::MatrixXd>& es = *solver;
    vectors.resize(nu, nu);
    for (int i = 0; i < nu; ++i) {
      const std::complex<double> l = es.eigenvalues()[i];
      const Eigen::VectorXcd v = es.eigenvectors().col(i);
      // Real shape: rotate by the phase of the largest entry.
      Eigen::Index imax = 0;
      v.cwiseAbs().maxCoeff(&imax);
      vectors.col(i) = (v * std::conj(v[imax]) / std::abs(v[imax])).real();
      // Flexible modes: omega^2 real and positive. A complex pair (|Im| not small) would mean a
      // non-conservative linearisation; it is not a natural mode and is skipped.
      if (l.real() > floor * floor && std::abs(l.imag()) <= 1e-6 * l.real()) order.push_back({std::sqrt(l.real()), i});
    }
  }
  std::sort(order.begin(), order.end());
  ModeShapes m;
  m.omega.resize(static_cast<Eigen::Index>(order.size()));
  m.shapes.resize(ny, static_cast<Eigen::Index>(order.size()));
  for (std::size_t k = 0; k < order.size(); ++k) {
    Eigen::VectorXd y = Cy * vectors.col(order[k].second);
    const double norm = y.norm();
    if (norm > 0) {
      Eigen::Index ymax = 0;
      y.cwiseAbs().maxCoeff(&ymax);
      y *= (y[ymax] < 0 ? -1.0 : 1.0) / norm;
    }
    const auto col = static_cast<Eigen::Index>(k);
    m.omega[col] = order[k].first;
    m.shapes.col(col) = y;
  }
  return m;
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
