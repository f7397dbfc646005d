#include "scoleid/identify/inverse/frf_misfit.h"

#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <string>
#include <thread>

namespace scoleid::identify {

namespace {

using Complex = std::complex<double>;
using ComplexSparse = Eigen::SparseMatrix<Complex>;
using ComplexVector = Eigen::VectorXcd;
constexpr double kTwoPi = 6.283185307179586476925286766559;

// Σ of the terms that carry coefficient j, per coefficient (empty where none does).
std::vector<SparseMatrix> per_coefficient(const std::vector<OperatorTerm>& terms, int ncoef, int ndof) {
  std::vector<SparseMatrix> out(static_cast<std::size_t>(ncoef), SparseMatrix(ndof, ndof));
  for (const auto& t : terms)
    if (t.coefficient >= 0) out[static_cast<std::size_t>(t.coefficient)] += t.matrix;
  return out;
}

// (iω)^o
// s^order: a displacement, velocity or acceleration per force (s = a + iω; iω without a window).
Complex rate_factor(Complex s, double order) {
  const int o = static_cast<int>(order);
  Complex f(1.0, 0.0);
  for (int i = 0; i < o; ++i) f *= s;
  return f;
}

}  // namespace

FrfMisfit::FrfMisfit(const StructuralModel& model, const Parameterization& params, io::FrfData data,
                     std::vector<int> sensors, int input, FrfMisfitOptions options)
    : model_(model), params_(params), data_(std::move(data)), sensors_(std::move(sensors)), input_(input),
      options_(options) {
  if (sensors_.size() != data_.channels.size())
    throw std::logic_error("FrfMisfit: one model sensor per channel is needed");
  if (input_ < 0 || input_ >= static_cast<int>(model_.inputs.size())) throw std::logic_error("FrfMisfit: no such input");
  if (data_.f_hz.empty()) throw std::logic_error("FrfMisfit: no lines");
  for (std::size_t s = 0; s < sensors_.size(); ++s) {
    const int m = sensors_[s];
    if (m < 0 || m >= static_cast<int>(model_.sensors.size())) throw std::logic_error("FrfMisfit: no such sensor");
    const auto& ch = data_.channels[s];
    if (ch.H.size() != data_.f_hz.size() || ch.variance.size() != data_.f_hz.size())
      throw std::logic_error("FrfMisfit: a channel's values and variances must match the lines");
    for (double v : ch.variance)
      if (!(v > 0.0) || !std::isfinite(v)) throw std::logic_error("FrfMisfit: variances must be finite and > 0");
    orders_.push_back(model_.sensors[static_cast<std::size_t>(m)].order);
  }
  active_ = data_.lines();
}

void FrfMisfit::set_horizon(double f) {
  const auto end = std::upper_bound(data_.f_hz.begin(), data_.f_hz.end(), f * (1.0 + 1e-12));
  active_ = std::max(1, static_cast<int>(end - data_.f_hz.begin()));
}

void FrfMisfit::evaluate_lines(const VectorXd& c, const MatrixXd& dcdq, Need need, int k0, int k1, Evaluation& e,
                               VectorXd& g_c) const {
  const int n = model_.ndof, S = static_cast<int>(sensors_.size()), ncoef = model_.ncoef;
  const AssembledModel a = assemble(model_, c);
  const ComplexSparse Mc = a.M.cast<Complex>(), Dc = a.D.cast<Complex>(), Kc = a.K.cast<Complex>();
  const ComplexVector b = a.loads[static_cast<std::size_t>(input_)].cast<Complex>();
  const auto Kj = per_coefficient(model_.stiffness, ncoef, n), Mj = per_coefficient(model_.mass, ncoef, n),
             Dj = per_coefficient(model_.damping, ncoef, n);
  const int input_coefficient = model_.inputs[static_cast<std::size_t>(input_)].coefficient;
  const VectorXd& b_unit = model_.inputs[static_cast<std::size_t>(input_)].vector;
  Eigen::MatrixXcd Ct(n, S);  // C_sᵀ
  for (int s = 0; s < S; ++s) Ct.col(s) = model_.sensors[static_cast<std::size_t>(sensors_[static_cast<std::size_t>(s)])].row.transpose().cast<Complex>();
  Eigen::SparseLU<ComplexSparse> lu;
  g_c = VectorXd::Zero(ncoef);
  Eigen::MatrixXcd dHdc(S, ncoef);
  for (int k = k0; k < k1; ++k) {
    // The complex frequency s = a + iω (a: the data's exponential window, frf_data.h decay).
    const Complex sk(data_.decay, kTwoPi * data_.f_hz[static_cast<std::size_t>(k)]);
    ComplexSparse Z = Kc + (sk * sk) * Mc + sk * Dc;
    lu.compute(Z);
    if (lu.info() != Eigen::Success)
      throw std::domain_error("FrfMisfit: the model's dynamic stiffness is singular at " + std::to_string(data_.f_hz[static_cast<std::size_t>(k)]) + " Hz");
    const ComplexVector U = lu.solve(b);
    std::vector<Complex> factor(static_cast<std::size_t>(S)), delta(static_cast<std::size_t>(S));
    for (int s = 0; s < S; ++s) {
      const auto& ch = data_.channels[static_cast<std::size_t>(s)];
      factor[static_cast<std::size_t>(s)] = rate_factor(sk, orders_[static_cast<std::size_t>(s)]);
      const Complex H = factor[static_cast<std::size_t>(s)] * Ct.col(s).transpose() * U;
      e.H(k, s) = H;
      const Complex d = H - ch.H[static_cast<std::size_t>(k)];
      delta[static_cast<std::size_t>(s)] = d;
      const double scale = std::sqrt(2.0 / ch.variance[static_cast<std::size_t>(k)]);
      e.r[2 * (k * S + s)] = scale * d.real();
      e.r[2 * (k * S + s) + 1] = scale * d.imag();
    }
    if (need == Need::Cost || k >= e.active) continue;
    // b_j − Z_j U per coefficient.
    const VectorXd Ur = U.real(), Ui = U.imag();
    // A real sparse matrix times U, without a complex copy of the matrix.
    auto times_U = [&](const SparseMatrix& A) -> ComplexVector {
      ComplexVector out(n);
      out.real() = A * Ur;
      out.imag() = A * Ui;
      return out;
    };
    auto source = [&](int j) {
      const auto jj = static_cast<std::size_t>(j);
      ComplexVector v = -times_U(Kj[jj]) - (sk * sk) * times_U(Mj[jj]) - sk * times_U(Dj[jj]);
      if (j == input_coefficient) v += b_unit.cast<Complex>();
      return v;
    };
    if (need == Need::Gradient) {
      ComplexVector rhs = ComplexVector::Zero(n);
      for (int s = 0; s < S; ++s) {
        const double var = data_.channels[static_cast<std::size_t>(s)].variance[static_cast<std::size_t>(k)];
        rhs += (std::conj(delta[static_cast<std::size_t>(s)]) * factor[static_cast<std::size_t>(s)] / var) * Ct.col(s);
      }
      const ComplexVector lambda = lu.solve(rhs);
      for (int j = 0; j < ncoef; ++j) g_c[j] += 2.0 * lambda.cwiseProduct(source(j)).sum().real();
      continue;
    }
    const Eigen::MatrixXcd Lambda = lu.solve(Ct);  // λ_s = Z⁻¹ C_sᵀ
    for (int j = 0; j < ncoef; ++j) {
      const ComplexVector v = source(j);
      for (int s = 0; s < S; ++s) dHdc(s, j) = factor[static_cast<std::size_t>(s)] * (Lambda.col(s).transpose() * v)(0);
    }
    const Eigen::MatrixXcd dHdq = dHdc * dcdq.cast<Complex>();
    for (int s = 0; s < S; ++s) {
      const double scale = std::sqrt(2.0 / data_.channels[static_cast<std::size_t>(s)].variance[static_cast<std::size_t>(k)]);
      e.jacobian.row(2 * (k * S + s)) = scale * dHdq.row(s).real();
      e.jacobian.row(2 * (k * S + s) + 1) = scale * dHdq.row(s).imag();
    }
  }
}

const FrfMisfit::Evaluation& FrfMisfit::evaluate(const VectorXd& q, Need need) {
  if (have_last_ && last_.q.size() == q.size() && last_.q == q && last_.active == active_ &&
      static_cast<int>(last_.need) >= static_cast<int>(need))
    return last_;
  VectorXd c;
  MatrixXd dcdq;
  params_.coefficients(q, c, dcdq);
  const int L = data_.lines(), S = static_cast<int>(sensors_.size()), P = params_.size();
  Evaluation e;
  e.q = q;
  e.need = need;
  e.active = active_;
  e.r.resize(2L * L * S);
  e.H.resize(L, S);
  if (need == Need::Jacobian) e.jacobian.resize(data_points(), P);
  const int threads = std::max(1, std::min(options_.threads, L / 8));
  std::vector<VectorXd> g(static_cast<std::size_t>(threads));
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(threads));
  auto work = [&](int t) {
    try {
      evaluate_lines(c, dcdq, need, L * t / threads, L * (t + 1) / threads, e, g[static_cast<std::size_t>(t)]);
    } catch (...) {
      errors[static_cast<std::size_t>(t)] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (auto& th : pool) th.join();
  for (const auto& err : errors)
    if (err) std::rethrow_exception(err);
  counters_.evaluations += 1;
  counters_.factorisations += L;
  e.J = 0.5 * e.r.head(data_points()).squaredNorm();
  if (need == Need::Gradient) {
    VectorXd g_c = VectorXd::Zero(model_.ncoef);
    for (const auto& gt : g) g_c += gt;
    e.gradient = dcdq.transpose() * g_c;
  } else if (need == Need::Jacobian) {
    e.gradient = e.jacobian.transpose() * e.r.head(data_points());
  }
  last_ = std::move(e);
  have_last_ = true;
  return last_;
}

double FrfMisfit::cost(const VectorXd& q) { return evaluate(q, Need::Cost).J; }

double FrfMisfit::cost_and_gradient(const VectorXd& q, VectorXd& gradient) {
  const Evaluation& e = evaluate(q, Need::Gradient);
  gradient = e.gradient;
  return e.J;
}

double FrfMisfit::gauss_newton(const VectorXd& q, VectorXd& gradient, MatrixXd& H, MisfitProfile* profile) {
  const Evaluation& e = evaluate(q, Need::Jacobian);
  gradient = e.gradient;
  H = e.jacobian.transpose() * e.jacobian;
  if (profile) *profile = profile_of(e);
  return e.J;
}

Misfit::MisfitProfile FrfMisfit::profile_of(const Evaluation& e) const {
  const int L = data_.lines(), S = static_cast<int>(sensors_.size());
  MisfitProfile p;
  p.t = data_.f_hz;
  p.misfit.assign(static_cast<std::size_t>(L), 0.0);
  for (int s = 0; s < S; ++s) {
    const auto& ch = data_.channels[static_cast<std::size_t>(s)];
    double misfit = 0.0, signal = 0.0;
    for (int k = 0; k < L; ++k) {
      misfit += 0.5 * (e.r[2 * (k * S + s)] * e.r[2 * (k * S + s)] + e.r[2 * (k * S + s) + 1] * e.r[2 * (k * S + s) + 1]);
      signal += std::norm(ch.H[static_cast<std::size_t>(k)]) / ch.variance[static_cast<std::size_t>(k)];
      p.misfit[static_cast<std::size_t>(k)] += std::max(0.0, misfit - (k + 1.0)) / std::max(signal, 1e-300) / S;
    }
  }
  return p;
}

Misfit::MisfitProfile FrfMisfit::misfit_profile(const VectorXd& q) { return profile_of(evaluate(q, Need::Cost)); }

VectorXd FrfMisfit::gauss_newton_product(const VectorXd& q, const VectorXd& v) {
  const Evaluation& e = evaluate(q, Need::Jacobian);
  return e.jacobian.transpose() * (e.jacobian * v);
}

double FrfMisfit::residuals(const VectorXd& q, VectorXd& r, MatrixXd* jacobian) {
  const Evaluation& e = evaluate(q, jacobian ? Need::Jacobian : Need::Cost);
  r = e.r.head(data_points());
  if (jacobian) *jacobian = e.jacobian;
  return e.J;
}

ComplexMatrix FrfMisfit::predict(const VectorXd& q) { return evaluate(q, Need::Cost).H; }

}  // namespace scoleid::identify
