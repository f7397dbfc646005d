#include "scoleid/identify/inverse/nonlinear_objective.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "scoleid/io/interrupt.h"

namespace scoleid::identify {

namespace {
constexpr double kDefectTol = 1e-12;
constexpr double kDefectContraction = 0.3;
constexpr int kMaxDefect = 12;
constexpr double kSensitivityStep = 1e-4;

// The transposed stage systems of the costate, (I − hγ J(Y_i))ᵀ Λ_i = rhs, solved by defect
// correction on a frozen factorisation of (I − hγ J_ref)ᵀ (J_ref = ∂f/∂y at a reference stage, by
// nonlinear_jacobian), refreshed when the step changes by more than 5 % or the correction stalls.
class StageAdjointSolver {
public:
  StageAdjointSolver(const ScoleNonlinear::Dynamics& dyn, double gamma, VectorXd scale, NonlinearCostateSummary& sum)
      : dyn_(dyn), gamma_(gamma), scale_(std::move(scale)), sum_(sum) {}

  // The factorisation for step h, refreshed at (y, in) unless it is for a step within 5 % of h.
  void prepare(const VectorXd& y, const VectorXd& in, double h) {
    if (!have_ref_ || std::abs(h / h_ref_ - 1.0) > 0.05) refresh(y, in, h);
  }

  // Λ for rhs at stage (y, in) of step h, JT(x) = J(y)ᵀ x; `t` names the step in an error.
  template <class Product>
  VectorXd solve(const VectorXd& rhs, const Product& JT, const VectorXd& y, const VectorXd& in, double h, double t) {
    VectorXd L = VectorXd::Zero(rhs.size());
    if (!(rhs.cwiseAbs().maxCoeff() > 0)) return L;
    for (int attempt = 0; attempt < 2; ++attempt) {
      L = lu_.solve(rhs);
      double prev = std::numeric_limits<double>::infinity();
      for (int m = 0; m < kMaxDefect; ++m) {
        // The correction, not the residual, is measured: with stiff modes (hγ‖J‖ ≫ 1) the
        // residual's rounding floor lies far above the solution's.
        const VectorXd dL = lu_.solve(VectorXd(rhs - L + h * gamma_ * JT(L)));
        L += dL;
        ++sum_.defect_iterations;
        const double size = dL.cwiseAbs().maxCoeff() / std::max(L.cwiseAbs().maxCoeff(), 1e-300);
        if (size <= kDefectTol) return L;
        if (m > 0 && size > kDefectContraction * prev) break;
        prev = size;
      }
      refresh(y, in, h);
    }
    throw std::runtime_error("nonlinear costate: the stage system does not converge at t = " + std::to_string(t) +
                             " (a fresh Jacobian did not help)");
  }

private:
  void refresh(const VectorXd& y, const VectorXd& in, double h) {
    const Eigen::Index n = y.size();
    const MatrixXd Jref = nonlinear_jacobian(dyn_, y, in, scale_);
    lu_.compute(MatrixXd::Identity(n, n) - h * gamma_ * Jref.transpose());  // (I − hγ J)ᵀ
    h_ref_ = h;
    have_ref_ = true;
    ++sum_.jacobians;
  }

  const ScoleNonlinear::Dynamics& dyn_;
  const double gamma_;
  const VectorXd scale_;
  NonlinearCostateSummary& sum_;
  Eigen::PartialPivLU<MatrixXd> lu_;
  double h_ref_ = 0.0;
  bool have_ref_ = false;
};

// One step's stages backwards (docs/theory.md §6.7): Λ_i from the stage adjoint solves, their
// share of the coefficient gradient added to gc; ybar, the adjoint at the step's end, becomes the
// adjoint at its start.
void step_adjoint(const ScoleNonlinear::Dynamics& dyn, const ButcherTable& tab, const NonlinearStep& st, StageAdjointSolver& stages,
                  std::vector<VectorXd>& Lam, VectorXd& ybar, VectorXd& gc, NonlinearCostateSummary& sum) {
  const int s = tab.stages;
  const auto n = ybar.size();
  const double gamma = tab.a(1, 1);
  const double h = st.h;
  stages.prepare(st.Y[static_cast<std::size_t>(s - 1)], st.inputs[static_cast<std::size_t>(s - 1)], h);
  for (int i = s - 1; i >= 1; --i) {
    const auto iu = static_cast<std::size_t>(i);
    VectorXd S = VectorXd::Zero(n);
    for (int k = i + 1; k < s; ++k) S += tab.a(k, i) * Lam[static_cast<std::size_t>(k)];
    auto JT = [&](const VectorXd& x) {
      ++sum.products;
      return dyn.derivative_vjp(st.Y[iu].data(), st.inputs[iu], st.F[iu], x);
    };
    VectorXd rhs = i == s - 1 ? ybar : VectorXd::Zero(n);
    if (S.cwiseAbs().maxCoeff() > 0) rhs += h * JT(S);
    const VectorXd L = stages.solve(rhs, JT, st.Y[iu], st.inputs[iu], h, st.t);
    Lam[iu] = L;
    const VectorXd Phi = gamma * L + S;
    if (Phi.cwiseAbs().maxCoeff() > 0) {
      gc += h * dyn.coefficient_vjp(st.Y[iu].data(), st.inputs[iu], st.F[iu], Phi);
      ++sum.products;
    }
  }
  VectorXd Phi0 = VectorXd::Zero(n), next = VectorXd::Zero(n);
  for (int i = 1; i < s; ++i) {
    Phi0 += tab.a(i, 0) * Lam[static_cast<std::size_t>(i)];
    next += Lam[static_cast<std::size_t>(i)];
  }
  if (Phi0.cwiseAbs().maxCoeff() > 0) {
    next += h * dyn.derivative_vjp(st.Y[0].data(), st.inputs[0], st.F[0], Phi0);
    gc += h * dyn.coefficient_vjp(st.Y[0].data(), st.inputs[0], st.F[0], Phi0);
    sum.products += 2;
  }
  ybar = next;
}
}  // namespace

NonlinearObjective::NonlinearObjective(const ScoleNonlinear& model, const Parameterization& params,
                                       std::vector<io::Signal> signals, const Measurements& data,
                                       NonlinearForwardOptions forward, std::vector<double> weights)
    : model_(model), params_(params), signals_(std::move(signals)), data_(data), fopt_(forward),
      given_weights_(std::move(weights)) {
  if (data_.t.size() < 2) throw std::invalid_argument("NonlinearObjective: at least two samples are needed");
  if (data_.sensors() != model_.sensors())
    throw std::invalid_argument("NonlinearObjective: the data have " + std::to_string(data_.sensors()) +
                                " sensors, the model " + std::to_string(model_.sensors()));
  if (!given_weights_.empty() && static_cast<int>(given_weights_.size()) != model_.sensors())
    throw std::invalid_argument("NonlinearObjective: one weight per sensor");
  set_horizon(data_.t.back());
}

int NonlinearObjective::samples_on_horizon() const {
  int k = 0;
  while (k < static_cast<int>(data_.t.size()) && data_.t[static_cast<std::size_t>(k)] <= T_ * (1 + 1e-12)) ++k;
  return k;
}

void NonlinearObjective::set_horizon(double T) {
  T_ = std::clamp(T, data_.t[1], data_.t.back());
  reset_weights();
}

void NonlinearObjective::reset_weights() {
  const int K = samples_on_horizon();
  tau_.assign(static_cast<std::size_t>(K), 0.0);
  for (int k = 0; k + 1 < K; ++k) {
    const double dt = data_.t[static_cast<std::size_t>(k + 1)] - data_.t[static_cast<std::size_t>(k)];
    tau_[static_cast<std::size_t>(k)] += 0.5 * dt;
    tau_[static_cast<std::size_t>(k + 1)] += 0.5 * dt;
  }
  const int ns = model_.sensors();
  R_.assign(static_cast<std::size_t>(ns), 1.0);
  if (!given_weights_.empty()) {
    R_ = given_weights_;
    return;
  }
  const double span = data_.t[static_cast<std::size_t>(K - 1)] - data_.t.front();
  for (int j = 0; j < ns; ++j) {
    const double ms = data_.z.col(j).head(K).squaredNorm() / K;
    R_[static_cast<std::size_t>(j)] = ms > 0 && span > 0 ? 1.0 / (span * ms) : 0.0;
  }
}

long NonlinearObjective::data_points() const { return static_cast<long>(samples_on_horizon()) * model_.sensors(); }

NonlinearResponse NonlinearObjective::forward(const VectorXd& c, bool keep_steps) {
  const int K = samples_on_horizon();
  const std::vector<double> times(data_.t.begin(), data_.t.begin() + K);
  auto r = simulate_nonlinear(model_.at(c), signals_, times, fopt_, VectorXd(), keep_steps);
  last_forward_ = r.summary;
  ++counters_.forward_solves;
  counters_.forward_seconds += r.summary.seconds;
  counters_.solver.steps += r.summary.steps;
  return r;
}

double NonlinearObjective::misfit_of(const NonlinearResponse& r) const {
  double J = 0.0;
  for (Eigen::Index k = 0; k < r.outputs.rows(); ++k)
    for (Eigen::Index j = 0; j < r.outputs.cols(); ++j) {
      const double e = r.outputs(k, j) - data_.z(k, j);
      J += 0.5 * tau_[static_cast<std::size_t>(k)] * R_[static_cast<std::size_t>(j)] * e * e;
    }
  return J;
}

Misfit::MisfitProfile NonlinearObjective::profile_of(const NonlinearResponse& r) const {
  MisfitProfile p;
  const Eigen::Index K = r.outputs.rows(), ns = r.outputs.cols();
  VectorXd num = VectorXd::Zero(ns), den = VectorXd::Zero(ns);
  for (Eigen::Index k = 0; k < K; ++k) {
    const double tau = k == 0 ? 0.0 : 0.5 * (data_.t[static_cast<std::size_t>(k)] - data_.t[static_cast<std::size_t>(k - 1)]);
    for (Eigen::Index j = 0; j < ns; ++j) {
      const double e1 = r.outputs(k, j) - data_.z(k, j);
      const double e0 = k == 0 ? 0.0 : r.outputs(k - 1, j) - data_.z(k - 1, j);
      const double z1 = data_.z(k, j), z0 = k == 0 ? 0.0 : data_.z(k - 1, j);
      num[j] += tau * (e0 * e0 + e1 * e1);
      den[j] += tau * (z0 * z0 + z1 * z1);
    }
    // The mean over all sensors (a sensor whose data are still zero counts 0), as objective.h.
    double m = 0.0;
    for (Eigen::Index j = 0; j < ns; ++j)
      if (den[j] > 0) m += num[j] / den[j];
    p.t.push_back(data_.t[static_cast<std::size_t>(k)]);
    p.misfit.push_back(ns > 0 ? m / static_cast<double>(ns) : 0.0);
  }
  return p;
}

MatrixXd NonlinearObjective::predict(const VectorXd& q) {
  VectorXd c;
  MatrixXd dcdq;
  params_.coefficients(q, c, dcdq);
  return forward(c, false).outputs;
}

double NonlinearObjective::cost(const VectorXd& q) {
  VectorXd c;
  MatrixXd dcdq;
  params_.coefficients(q, c, dcdq);
  return misfit_of(forward(c, false));
}

double NonlinearObjective::cost_and_gradient(const VectorXd& q, VectorXd& gradient) {
  VectorXd c, gc;
  MatrixXd dcdq;
  params_.coefficients(q, c, dcdq);
  const double J = cost_and_coefficient_gradient(c, gc);
  gradient = dcdq.transpose() * gc;
  return J;
}

double NonlinearObjective::cost_and_coefficient_gradient(const VectorXd& c, VectorXd& gc) {
  const NonlinearResponse r = forward(c, true);
  const double J = misfit_of(r);
  const auto clock0 = std::chrono::steady_clock::now();
  const auto dyn = model_.at(c);
  const ButcherTable& tab = nonlinear_table();
  const int s = tab.stages, n = model_.state_size(), nu = model_.speeds();
  const double gamma = tab.a(1, 1);
  NonlinearCostateSummary sum;
  gc = VectorXd::Zero(model_.coefficients());

  // The frozen transposed Newton matrix of the defect correction, on the states' scale.
  VectorXd scale = VectorXd::Constant(n, 1e-6);
  for (const auto& y : r.states) scale = scale.cwiseMax(y.cwiseAbs());
  StageAdjointSolver stages(dyn, gamma, scale, sum);

  // A sample's share: ρ = τ R (z − z̃); ∂/∂y directly and through u̇ = f_u(y).
  auto sample_adjoint = [&](int k, VectorXd& ybar) {
    const VectorXd& y = r.states[static_cast<std::size_t>(k)];
    const VectorXd& in = r.sample_inputs[static_cast<std::size_t>(k)];
    VectorXd yd(n), udot;
    dyn.derivative(y.data(), in, yd.data(), &udot);
    VectorXd rho(model_.sensors());
    for (int j = 0; j < rho.size(); ++j)
      rho[j] = tau_[static_cast<std::size_t>(k)] * R_[static_cast<std::size_t>(j)] *
               (r.outputs(k, j) - data_.z(k, j));
    VectorXd dy, da;
    dyn.outputs_vjp(y.data(), udot, rho, dy, da);
    ybar += dy;
    if (da.cwiseAbs().maxCoeff() > 0) {
      VectorXd lam = VectorXd::Zero(n);
      lam.tail(nu) = da;
      ybar += dyn.derivative_vjp(y.data(), in, yd, lam);
      gc += dyn.coefficient_vjp(y.data(), in, yd, lam);
      sum.products += 2;
    }
  };

  VectorXd ybar = VectorXd::Zero(n);
  std::vector<VectorXd> Lam(static_cast<std::size_t>(s));
  for (auto it = r.steps.rbegin(); it != r.steps.rend(); ++it) {
    const NonlinearStep& st = *it;
    if (st.sample >= 0) {
      io::check_interrupt();
      sample_adjoint(st.sample, ybar);
    }
    step_adjoint(dyn, tab, st, stages, Lam, ybar, gc, sum);
  }
  // The first sample (the given initial state): only its u̇ depends on c.
  {
    VectorXd unused = VectorXd::Zero(n);
    sample_adjoint(0, unused);
  }
  sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock0).count();
  last_costate_ = sum;
  ++counters_.costate_solves;
  ++counters_.gradient_evaluations;
  counters_.costate_seconds += sum.seconds;
  return J;
}

MatrixXd NonlinearObjective::output_sensitivities(const VectorXd& q) {
  const int P = size(), K = samples_on_horizon(), ns = model_.sensors();
  MatrixXd G(static_cast<Eigen::Index>(K) * ns, P);
  for (int i = 0; i < P; ++i) {
    const double d = kSensitivityStep * std::max(std::abs(q[i]), 1e-12);
    VectorXd qp = q, qm = q;
    qp[i] += d;
    qm[i] -= d;
    const MatrixXd S = (predict(qp) - predict(qm)) / (2 * d);
    counters_.sensitivity_solves += 2;
    for (int k = 0; k < K; ++k)
      for (int j = 0; j < ns; ++j) G(static_cast<Eigen::Index>(k) * ns + j, i) = S(k, j);
  }
  return G;
}

double NonlinearObjective::gauss_newton(const VectorXd& q, VectorXd& gradient, MatrixXd& H, MisfitProfile* profile) {
  const double J = cost_and_gradient(q, gradient);
  const int P = size();
  const NonlinearForwardSummary keep = last_forward_;
  const int K = samples_on_horizon(), ns = model_.sensors();
  const MatrixXd G = output_sensitivities(q);
  H = MatrixXd::Zero(P, P);
  for (int k = 0; k < K; ++k)
    for (int j = 0; j < ns; ++j) {
      const VectorXd s = G.row(static_cast<Eigen::Index>(k) * ns + j).transpose();
      H += tau_[static_cast<std::size_t>(k)] * R_[static_cast<std::size_t>(j)] * s * s.transpose();
    }
  last_forward_ = keep;
  if (profile) *profile = misfit_profile(q);
  return J;
}

Misfit::MisfitProfile NonlinearObjective::misfit_profile(const VectorXd& q) {
  // Over the whole record; the horizon is restored whatever happens (a trial point whose forward
  // run fails must not leave the continuation on the full record).
  struct Restore {
    NonlinearObjective& o;
    double T;
    ~Restore() { o.set_horizon(T); }
  } restore{*this, T_};
  set_horizon(data_.t.back());
  VectorXd c;
  MatrixXd dcdq;
  params_.coefficients(q, c, dcdq);
  return profile_of(forward(c, false));
}

VectorXd NonlinearObjective::gauss_newton_product(const VectorXd& q, const VectorXd& v) {
  VectorXd g;
  MatrixXd H;
  gauss_newton(q, g, H);
  return H * v;
}

}  // namespace scoleid::identify
