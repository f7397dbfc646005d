#include "scoleid/identify/objective.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace scoleid::identify {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// 3-point Gauss–Legendre on [0, 1]
constexpr double kGx[3] = {0.1127016653792583, 0.5, 0.8872983346207417};
constexpr double kGw[3] = {0.2777777777777778, 0.4444444444444444, 0.2777777777777778};
}  // namespace

Objective::Objective(const StructuralModel& model, const Parameterization& params, std::vector<io::Signal> inputs,
                     Measurements data, ObjectiveOptions options)
    : model_(model), params_(params), inputs_(std::move(inputs)), data_(std::move(data)), options_(std::move(options)) {
  if (inputs_.size() != model_.inputs.size()) throw std::invalid_argument("Objective: one signal per model input");
  if (data_.sensors() != static_cast<int>(model_.sensors.size()))
    throw std::invalid_argument("Objective: one measurement column per model sensor");
  if (data_.t.size() < 2) throw std::invalid_argument("Objective: at least two samples");
  C_ = model_.output_matrix();
  T_ = data_.t.back();
  const double t0 = data_.t.front();
  const int ns = data_.sensors();
  if (!options_.weights.empty()) {
    if (static_cast<int>(options_.weights.size()) != ns) throw std::invalid_argument("Objective: one weight per sensor");
    R_ = options_.weights;
  } else {
    R_.assign(static_cast<std::size_t>(ns), 1.0);
    for (int k = 0; k < ns; ++k) {
      const double ms = data_.z.col(k).squaredNorm() / static_cast<double>(data_.z.rows());
      if (ms > 0) R_[static_cast<std::size_t>(k)] = 1.0 / ((T_ - t0) * ms);
    }
  }
  auto add_terms = [&](const std::vector<OperatorTerm>& ts, int kind) {
    for (const auto& t : ts) {
      if (t.coefficient < 0) continue;
      TermEntries e{t.coefficient, kind, {}, {}, {}};
      for (int k = 0; k < t.matrix.outerSize(); ++k)
        for (SparseMatrix::InnerIterator it(t.matrix, k); it; ++it) {
          e.row.push_back(static_cast<int>(it.row()));
          e.col.push_back(static_cast<int>(it.col()));
          e.value.push_back(it.value());
        }
      terms_.push_back(std::move(e));
    }
  };
  add_terms(model_.mass, 0);
  add_terms(model_.damping, 1);
  add_terms(model_.stiffness, 2);
  for (const auto& s : inputs_)
    for (double b : s.breakpoints())
      if (b > t0 && b < T_) breakpoints_.push_back(b);
  std::sort(breakpoints_.begin(), breakpoints_.end());
  breakpoints_.erase(std::unique(breakpoints_.begin(), breakpoints_.end()), breakpoints_.end());
}

Objective::Setup Objective::setup(const VectorXd& q) const {
  Setup s;
  for (int i = 0; i < q.size(); ++i)
    if (!(q[i] > 0.0) || !std::isfinite(q[i]))
      throw std::domain_error("parameter " + params_.names()[static_cast<std::size_t>(i)] + " left the positive range");
  params_.coefficients(q, s.c, s.dcdq);
  s.ops = assemble(model_, s.c);
  return s;
}

Trajectory Objective::forward(const SecondOrderSolver& solver, const Setup& s) {
  const auto t0 = Clock::now();
  const auto& loads = s.ops.loads;
  const int n = model_.ndof;
  SecondOrderSolver::Forcing f = [&](double t, double* F) {
    Eigen::Map<VectorXd> Fm(F, n);
    for (std::size_t i = 0; i < loads.size(); ++i) {
      const double fi = inputs_[i](t);
      if (fi != 0.0) Fm += fi * loads[i];
    }
  };
  SolverSummary sum;
  Trajectory u = solver.solve(data_.t.front(), T_, f, breakpoints_, &sum);
  counters_.solver.Accumulate(sum);
  ++counters_.forward_solves;
  counters_.forward_seconds += since(t0);
  return u;
}

std::vector<double> Objective::union_grid(const std::vector<const std::vector<double>*>& sets) const {
  std::vector<double> g;
  for (const auto* s : sets) g.insert(g.end(), s->begin(), s->end());
  g.insert(g.end(), data_.t.begin(), data_.t.end());
  std::sort(g.begin(), g.end());
  g.erase(std::unique(g.begin(), g.end()), g.end());
  const double t0 = data_.t.front();
  g.erase(std::remove_if(g.begin(), g.end(), [&](double t) { return t < t0 || t > T_; }), g.end());
  return g;
}

double Objective::cost_of(const Trajectory& u) const {
  const int n = model_.ndof, ns = data_.sensors();
  const auto grid = union_grid({&u.times()});
  VectorXd x(n), v(n), z(ns);
  double J = 0.0;
  for (std::size_t k = 0; k + 1 < grid.size(); ++k) {
    const double h = grid[k + 1] - grid[k];
    for (int g = 0; g < 3; ++g) {
      const double t = grid[k] + kGx[g] * h;
      u.eval(t, x.data(), v.data());
      data_.eval(t, z.data());
      const VectorXd r = C_ * x - z;
      double e = 0.0;
      for (int j = 0; j < ns; ++j) e += R_[static_cast<std::size_t>(j)] * r[j] * r[j];
      J += 0.5 * kGw[g] * h * e;
    }
  }
  return J;
}

double Objective::cost(const VectorXd& q) {
  const Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  const Trajectory u = forward(solver, s);
  const auto t0 = Clock::now();
  const double J = cost_of(u);
  counters_.quadrature_seconds += since(t0);
  return J;
}

double Objective::cost_and_gradient(const VectorXd& q, VectorXd& gradient) {
  const Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  const Trajectory u = forward(solver, s);
  const int n = model_.ndof, ns = data_.sensors();
  const double t0 = data_.t.front();

  // Costate backward: P(τ) = p(T − τ), τ ∈ [0, T − t0].
  auto tc = Clock::now();
  VectorXd xb(n), vb(n), zb(ns), rb(ns);
  const MatrixXd CtR = C_.transpose() * Eigen::Map<const VectorXd>(R_.data(), ns).asDiagonal();
  SecondOrderSolver::Forcing g = [&](double tau, double* F) {
    const double t = T_ - tau;
    u.eval(t, xb.data(), vb.data());
    data_.eval(t, zb.data());
    rb = C_ * xb - zb;
    Eigen::Map<VectorXd>(F, n) = -CtR * rb;
  };
  std::vector<double> bp_tau;
  for (double b : breakpoints_) bp_tau.push_back(T_ - b);
  std::sort(bp_tau.begin(), bp_tau.end());
  SolverSummary sum;
  const Trajectory P = solver.solve(0.0, T_ - t0, g, bp_tau, &sum);
  counters_.solver.Accumulate(sum);
  ++counters_.costate_solves;
  counters_.costate_seconds += since(tc);

  // Quadratures: cost and coefficient gradients.
  const auto tq = Clock::now();
  std::vector<double> ptimes;
  ptimes.reserve(P.size());
  for (double tau : P.times()) ptimes.push_back(T_ - tau);
  const auto grid = union_grid({&u.times(), &ptimes});
  VectorXd x(n), v(n), p(n), pd(n), z(ns), gc = VectorXd::Zero(model_.ncoef), w(n);
  double J = 0.0;
  for (std::size_t k = 0; k + 1 < grid.size(); ++k) {
    const double h = grid[k + 1] - grid[k];
    for (int gq = 0; gq < 3; ++gq) {
      const double t = grid[k] + kGx[gq] * h, wt = kGw[gq] * h;
      u.eval(t, x.data(), v.data());
      P.eval(T_ - t, p.data(), pd.data());
      pd = -pd;  // ṗ(t) = −P'(T − t)
      data_.eval(t, z.data());
      const VectorXd r = C_ * x - z;
      double e = 0.0;
      for (int j = 0; j < ns; ++j) e += R_[static_cast<std::size_t>(j)] * r[j] * r[j];
      J += 0.5 * wt * e;
      // Mass term by parts: −ṗᵀ M_j u̇; damping pᵀ D_j u̇; stiffness pᵀ K_j u.
      for (const auto& e : terms_) {
        const double* left = e.kind == 0 ? pd.data() : p.data();
        const double* right = e.kind == 2 ? x.data() : v.data();
        double acc = 0.0;
        for (std::size_t m = 0; m < e.value.size(); ++m) acc += left[e.row[m]] * e.value[m] * right[e.col[m]];
        gc[e.coefficient] += (e.kind == 0 ? -wt : wt) * acc;
      }
      for (std::size_t i = 0; i < model_.inputs.size(); ++i) {
        const int ci = model_.inputs[i].coefficient;
        if (ci >= 0) gc[ci] -= wt * inputs_[i](t) * p.dot(model_.inputs[i].vector);
      }
    }
  }
  gradient = s.dcdq.transpose() * gc;
  ++counters_.gradient_evaluations;
  counters_.quadrature_seconds += since(tq);
  return J;
}

Trajectory Objective::sensitivity(const SecondOrderSolver& solver, const Setup& s, const Trajectory& u, int i) const {
  const int n = model_.ndof;
  // ∂_i M, ∂_i D, ∂_i K, ∂_i b assembled once.
  VectorXd dcol = s.dcdq.col(i);
  // Constant terms (coefficient −1) do not enter the derivative.
  auto only_coef = [&](const std::vector<OperatorTerm>& terms) {
    SparseMatrix A(n, n);
    for (const auto& t : terms)
      if (t.coefficient >= 0 && dcol[t.coefficient] != 0.0) A += dcol[t.coefficient] * t.matrix;
    return A;
  };
  const SparseMatrix dMc = only_coef(model_.mass), dDc = only_coef(model_.damping), dKc = only_coef(model_.stiffness);
  std::vector<VectorXd> db;
  for (const auto& in : model_.inputs)
    db.push_back(in.coefficient >= 0 ? VectorXd(dcol[in.coefficient] * in.vector) : VectorXd(VectorXd::Zero(n)));
  VectorXd x(n), v(n), a(n), Fe(n);
  SecondOrderSolver::Forcing f = [&](double t, double* F) {
    u.eval(t, x.data(), v.data());
    Fe.setZero();
    for (std::size_t k = 0; k < s.ops.loads.size(); ++k) Fe += inputs_[k](t) * s.ops.loads[k];
    solver.acceleration(Fe.data(), x.data(), v.data(), a.data());
    Eigen::Map<VectorXd> Fm(F, n);
    Fm = -(dMc * a + dDc * v + dKc * x);
    for (std::size_t k = 0; k < db.size(); ++k) Fm += inputs_[k](t) * db[k];
  };
  return solver.solve(data_.t.front(), T_, f, breakpoints_, nullptr);
}

double Objective::gauss_newton(const VectorXd& q, VectorXd& gradient, MatrixXd& H) {
  const Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  const Trajectory u = forward(solver, s);
  const int P = size(), n = model_.ndof, ns = data_.sensors();
  auto ts = Clock::now();
  std::vector<Trajectory> S;
  for (int i = 0; i < P; ++i) S.push_back(sensitivity(solver, s, u, i));
  counters_.sensitivity_solves += P;
  counters_.sensitivity_seconds += since(ts);

  const auto tq = Clock::now();
  const auto grid = union_grid({&u.times()});
  VectorXd x(n), v(n), z(ns), si(n), sv(n);
  MatrixXd CS(ns, P);
  gradient = VectorXd::Zero(P);
  H = MatrixXd::Zero(P, P);
  const Eigen::Map<const VectorXd> Rv(R_.data(), ns);
  double J = 0.0;
  for (std::size_t k = 0; k + 1 < grid.size(); ++k) {
    const double h = grid[k + 1] - grid[k];
    for (int gq = 0; gq < 3; ++gq) {
      const double t = grid[k] + kGx[gq] * h, wt = kGw[gq] * h;
      u.eval(t, x.data(), v.data());
      data_.eval(t, z.data());
      const VectorXd r = C_ * x - z;
      for (int i = 0; i < P; ++i) {
        S[static_cast<std::size_t>(i)].eval(t, si.data(), sv.data());
        CS.col(i) = C_ * si;
      }
      const MatrixXd RCS = Rv.asDiagonal() * CS;
      J += 0.5 * wt * r.dot(Rv.cwiseProduct(r));
      gradient += wt * RCS.transpose() * r;
      H += wt * CS.transpose() * RCS;
    }
  }
  counters_.quadrature_seconds += since(tq);
  return J;
}

VectorXd Objective::finite_difference_gradient(const VectorXd& q, double h) {
  VectorXd g(q.size());
  for (int i = 0; i < q.size(); ++i) {
    VectorXd qp = q, qm = q;
    const double d = h * q[i];
    qp[i] += d;
    qm[i] -= d;
    g[i] = (cost(qp) - cost(qm)) / (2.0 * d);
  }
  return g;
}

MatrixXd Objective::predict(const VectorXd& q) {
  const Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  const Trajectory u = forward(solver, s);
  const int n = model_.ndof;
  MatrixXd Y(static_cast<Eigen::Index>(data_.t.size()), data_.sensors());
  VectorXd x(n), v(n);
  for (std::size_t k = 0; k < data_.t.size(); ++k) {
    u.eval(data_.t[k], x.data(), v.data());
    Y.row(static_cast<Eigen::Index>(k)) = (C_ * x).transpose();
  }
  return Y;
}

MatrixXd Objective::output_sensitivities(const VectorXd& q) {
  const Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  const Trajectory u = forward(solver, s);
  const int P = size(), n = model_.ndof, ns = data_.sensors();
  MatrixXd G(static_cast<Eigen::Index>(data_.t.size()) * ns, P);
  VectorXd x(n), v(n);
  for (int i = 0; i < P; ++i) {
    const Trajectory Si = sensitivity(solver, s, u, i);
    ++counters_.sensitivity_solves;
    for (std::size_t k = 0; k < data_.t.size(); ++k) {
      Si.eval(data_.t[k], x.data(), v.data());
      G.block(static_cast<Eigen::Index>(k) * ns, i, ns, 1) = C_ * x;
    }
  }
  return G;
}

}  // namespace scoleid::identify
