#include "scoleid/identify/inverse/objective.h"
#include "scoleid/identify/point_failure.h"

#include <algorithm>
#include <Eigen/Eigenvalues>
#include <array>
#include <memory>
#include <cmath>
#include <functional>
#include <limits>
#include <exception>
#include <stdexcept>
#include <thread>

#include "scoleid/identify/inverse/coefficient_quadrature.h"
#include "scoleid/identify/fe/lowest_modes.h"
#include "scoleid/identify/fe/modal.h"
#include "scoleid/io/interrupt.h"

namespace scoleid::identify {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Appends the outputs (C x, C v, C a) at t to `out`: what a checkpointed costate reads (§7.9).
void push_outputs(const Eigen::SparseMatrix<double, Eigen::RowMajor>& C, Trajectory& out, double t, const double* x,
                  const double* v, const double* a) {
  const auto n = C.cols();
  const Eigen::VectorXd y = C * Eigen::Map<const Eigen::VectorXd>(x, n), yv = C * Eigen::Map<const Eigen::VectorXd>(v, n),
                        ya = C * Eigen::Map<const Eigen::VectorXd>(a, n);
  out.push(t, y.data(), yv.data(), ya.data());
}

// The cubic Hermite basis at t on [t0, t0 + h]: weights of the ends' values (h00, h01) and of their
// slopes (h10, h11, h folded in), as Trajectory::eval interpolates between recorded points.
struct HermiteWeights {
  double h00, h10, h01, h11;
};
HermiteWeights hermite_weights(double t, double t0, double h) {
  const double sr = (t - t0) / h, s2 = sr * sr, s3 = s2 * sr;
  return {2 * s3 - 3 * s2 + 1, (s3 - 2 * s2 + sr) * h, -2 * s3 + 3 * s2, (s3 - s2) * h};
}

// The tangents' outputs at the sample times in (t_prev, t1] (all up to t1 at the first point),
// Hermite-interpolated between two recorded points in output space — Yx = C X + C₁ V and
// Yv = C V + C₁ A of every column at each point, the outputs being linear in (X, V) without
// acceleration sensors — into rows (sample · sensors) of G. The one interpolation of the
// Gauss–Newton sweep and output_sensitivities, so the two give the same numbers.
void sample_output_rows(const std::vector<double>& times, std::size_t& next, bool have_prev, double t_prev, double t1,
                        const Eigen::MatrixXd& Yx0, const Eigen::MatrixXd& Yv0, const Eigen::MatrixXd& Yx1,
                        const Eigen::MatrixXd& Yv1, Eigen::MatrixXd& Ys, Eigen::MatrixXd& G) {
  const Eigen::Index ns = Yx1.rows(), P = Yx1.cols() - 1;
  for (; next < times.size() && times[next] <= t1; ++next) {
    const Eigen::Index row = static_cast<Eigen::Index>(next) * ns;
    const double h = have_prev ? t1 - t_prev : 0.0;
    if (!(h > 0)) {
      G.block(row, 0, ns, P) = Yx1.rightCols(P);
      continue;
    }
    const auto [h00, h10, h01, h11] = hermite_weights(times[next], t_prev, h);
    Ys = h00 * Yx0 + h10 * Yv0 + h01 * Yx1 + h11 * Yv1;
    G.block(row, 0, ns, P) = Ys.rightCols(P);
  }
}

// The Gauss–Newton sums (§7.1) over Gauss points of weight wt, with residual r, output
// sensitivities CS (sensors × P) and the sensors' weights R (>= 0):
//   J += ½ wt rᵀ R r,   g += wt (CS)ᵀ R r,   H += wt (CS)ᵀ R (CS).
// J and g point by point; for H the points' scaled rows √(wt R) CS are gathered (transposed,
// P × rows) and taken in one symmetric rank update per kGaussNewtonBlock points (half of H's
// products, in blocks the matrix kernel runs at speed); `finish` flushes the last block and fills
// H's upper triangle.
class GaussNewtonSums {
public:
  static constexpr int kGaussNewtonBlock = 32;
  GaussNewtonSums(Eigen::Index P, const Eigen::Ref<const Eigen::VectorXd>& R, double& J, Eigen::VectorXd& gradient,
                  Eigen::MatrixXd& H)
      : R_(R), J_(J), g_(gradient), H_(H), rows_(P, kGaussNewtonBlock * R.size()) {}
  void add(double wt, const Eigen::VectorXd& r, const Eigen::Ref<const Eigen::MatrixXd>& CS) {
    const Eigen::Index ns = r.size();
    double e = 0.0;
    for (Eigen::Index j = 0; j < ns; ++j) e += R_[j] * r[j] * r[j];
    J_ += 0.5 * wt * e;
    RCS_ = R_.asDiagonal() * CS;
    g_ += wt * RCS_.transpose() * r;
    if (used_ + ns > rows_.cols()) flush();
    for (Eigen::Index j = 0; j < ns; ++j) rows_.col(used_ + j) = std::sqrt(wt * R_[j]) * CS.row(j).transpose();
    used_ += ns;
  }
  void finish() {
    flush();
    H_.triangularView<Eigen::StrictlyUpper>() = H_.transpose();
  }

private:
  void flush() {
    if (used_ == 0) return;
    H_.selfadjointView<Eigen::Lower>().rankUpdate(rows_.leftCols(used_));
    used_ = 0;
  }
  const Eigen::VectorXd R_;
  double& J_;
  Eigen::VectorXd& g_;
  Eigen::MatrixXd& H_;
  Eigen::MatrixXd rows_, RCS_;
  Eigen::Index used_ = 0;
};

// 3-point Gauss–Legendre on [0, 1]
constexpr double kGx[3] = {0.1127016653792583, 0.5, 0.8872983346207417};
constexpr double kGw[3] = {0.2777777777777778, 0.4444444444444444, 0.2777777777777778};

// The quadrature walker: the three-point Gauss–Legendre rule on every interval of `grid`
// (docs/theory.md §6.4), f(t, weight) at each point in order, then interval_done(its right end).
template <class F, class Done>
void for_each_gauss_point(const std::vector<double>& grid, F&& f, Done&& interval_done) {
  for (std::size_t k = 0; k + 1 < grid.size(); ++k) {
    const double h = grid[k + 1] - grid[k];
    for (int gq = 0; gq < 3; ++gq) f(grid[k] + kGx[gq] * h, kGw[gq] * h);
    interval_done(grid[k + 1]);
  }
}
template <class F>
void for_each_gauss_point(const std::vector<double>& grid, F&& f) {
  for_each_gauss_point(grid, std::forward<F>(f), [](double) {});
}

// 2-point Gauss–Legendre on [0, 1]: 1/2 ∓ 1/(2√3), weights 1/2. Eq. 25's coefficient integrand with
// displacement sensors (docs/theory.md §6.4): f(t, weight) at both points of every interval of `grid`.
constexpr double kG2x[2] = {0.21132486540518711775, 0.78867513459481288225};
template <class F>
void for_each_two_point(const std::vector<double>& grid, F&& f) {
  for (std::size_t k = 0; k + 1 < grid.size(); ++k) {
    const double h = grid[k + 1] - grid[k];
    for (int gq = 0; gq < 2; ++gq) f(grid[k] + kG2x[gq] * h, 0.5 * h);
  }
}

// A quadrature grid sorted, with points closer than rounding (1e-12 relative) merged into the
// first: the state's and the costate's grids mirror each other (t = T − τ) and meet again only up
// to rounding, and a sliver of 1e-16 s between them would cost three Gauss points for nothing.
void sort_grid(std::vector<double>& g) {
  std::sort(g.begin(), g.end());
  g.erase(std::unique(g.begin(), g.end(), [](double a, double b) { return b - a <= 1e-12 * std::max(1.0, std::abs(a)); }),
          g.end());
}

// X = A⁺ B for a symmetric positive semidefinite A: scaled to unit diagonal, then the eigenvalues
// above 1e-12 of the largest inverted and the others dropped (a direction the data do not see, such as
// a mode with a node at every sensor, gets coefficient zero instead of an arbitrary one).
MatrixXd pseudo_solve(const MatrixXd& A, const MatrixXd& B) {
  const Eigen::Index m = A.rows();
  VectorXd d(m);
  for (Eigen::Index i = 0; i < m; ++i) d[i] = A(i, i) > 0 ? 1.0 / std::sqrt(A(i, i)) : 1.0;
  const MatrixXd As = d.asDiagonal() * A * d.asDiagonal();
  Eigen::SelfAdjointEigenSolver<MatrixXd> es(0.5 * (As + As.transpose()));
  const VectorXd& lam = es.eigenvalues();
  const double top = lam.size() > 0 ? lam.maxCoeff() : 0.0;
  VectorXd inv = VectorXd::Zero(m);
  for (Eigen::Index i = 0; i < m; ++i)
    if (top > 0 && lam[i] > 1e-12 * top) inv[i] = 1.0 / lam[i];
  const MatrixXd& V = es.eigenvectors();
  return d.asDiagonal() * (V * inv.asDiagonal() * V.transpose()) * (d.asDiagonal() * B);
}
}  // namespace

Objective::Objective(const StructuralModel& model, const Parameterization& params, std::vector<io::Signal> inputs,
                     Measurements data, ObjectiveOptions options)
    : model_(model), params_(params), inputs_(std::move(inputs)), data_(std::move(data)), options_(std::move(options)) {
  if (inputs_.size() != model_.inputs.size()) throw std::invalid_argument("Objective: one signal per model input");
  if (data_.sensors() != static_cast<int>(model_.sensors.size()))
    throw std::invalid_argument("Objective: one measurement column per model sensor");
  if (data_.t.size() < 2) throw std::invalid_argument("Objective: at least two samples");
  C_ = model_.output_matrix(0);
  Cs_ = C_.sparseView(0.0, 0.0);
  if (model_.has_rate_outputs()) {
    C1_ = model_.output_matrix(1);
    C2_ = model_.output_matrix(2);
    accelerations_ = C2_.cwiseAbs().maxCoeff() > 0.0;
  }
  T_ = data_.t.back();
  const double t0 = data_.t.front();
  response_start_ = t0;
  {
    std::size_t onset = data_.t.size();
    for (const auto& sig : inputs_) {
      double peak = 0.0;
      for (double t : data_.t) peak = std::max(peak, std::abs(sig(t)));
      if (!(peak > 0)) continue;
      for (std::size_t i = 0; i < data_.t.size() && i < onset; ++i)
        if (std::abs(sig(data_.t[i])) > 0.05 * peak) onset = i;
    }
    if (onset < data_.t.size() && data_.t[onset] - t0 > 0.05 * (data_.t.back() - t0)) response_start_ = data_.t[onset];
  }
  if (options_.initial_state_modes > 0) {
    make_initial_state_basis();
    response_start_ = t0;  // a moving start has no quiet pre-trigger to skip
  }
  const int ns = data_.sensors();
  noise_share();
  if (!options_.weights.empty()) {
    if (static_cast<int>(options_.weights.size()) != ns) throw std::invalid_argument("Objective: one weight per sensor");
    // (A weight is a sensor's share of J: zero leaves the sensor out; a negative one would make J
    // and the Gauss–Newton matrix indefinite.)
    for (std::size_t k = 0; k < options_.weights.size(); ++k)
      if (!(options_.weights[k] >= 0.0 && std::isfinite(options_.weights[k]))) {
        char value[32];
        std::snprintf(value, sizeof value, "%.6g", options_.weights[k]);
        const std::string name = k < data_.names.size() ? "'" + data_.names[k] + "'" : "#" + std::to_string(k + 1);
        throw std::invalid_argument("Objective: the weight of sensor " + name + " is " + value +
                                    "; weights must be finite and >= 0");
      }
    R_ = options_.weights;
  } else {
    default_weights();
  }
  for (const auto& s : inputs_)
    for (double b : s.breakpoints())
      if (b > t0 && b < T_) breakpoints_.push_back(b);
  std::sort(breakpoints_.begin(), breakpoints_.end());
  breakpoints_.erase(std::unique(breakpoints_.begin(), breakpoints_.end()), breakpoints_.end());
}

void Objective::default_weights() {
  const int ns = data_.sensors();
  const double t0 = data_.t.front();
  R_.assign(static_cast<std::size_t>(ns), 1.0);
  for (int k = 0; k < ns; ++k) {
    double sum = 0.0;
    long count = 0;
    for (std::size_t i = 0; i < data_.t.size() && data_.t[i] <= T_; ++i, ++count) {
      const double z = data_.z(static_cast<Eigen::Index>(i), k);
      sum += z * z;
    }
    const double ms = count > 0 ? sum / static_cast<double>(count) : 0.0;
    if (ms > 0) R_[static_cast<std::size_t>(k)] = 1.0 / ((T_ - t0) * ms);
  }
}

void Objective::set_horizon(double T) {
  const auto& t = data_.t;
  T_ = std::clamp(T, t[1], t.back());
  if (options_.weights.empty()) default_weights();
}

long Objective::data_points() const {
  long n = 0;
  for (double t : data_.t)
    if (t <= T_) ++n;
  return n * data_.sensors();
}

double Misfit::MisfitProfile::longest_within(double bound) const {
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < t.size(); ++i)
    if (misfit[i] <= bound) best = t[i];
  return best;
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

SecondOrderSolver::Forcing Objective::state_forcing(const Setup& s) const {
  const auto& loads = s.ops.loads;
  const int n = model_.ndof;
  return [this, &loads, n](double t, double* F) {
    Eigen::Map<VectorXd> Fm(F, n);
    for (std::size_t i = 0; i < loads.size(); ++i) {
      const double fi = inputs_[i](t);
      if (fi != 0.0) Fm += fi * loads[i];
    }
  };
}

VectorXd Objective::output_at(const Setup& s, const SecondOrderSolver& solver, double t, const VectorXd& x,
                              const VectorXd& v, VectorXd* a) const {
  if (C1_.size() == 0) return C_ * x;
  VectorXd y = C_ * x + C1_ * v;
  if (accelerations_) {
    const int n = model_.ndof;
    VectorXd F = VectorXd::Zero(n), acc(n);
    for (std::size_t i = 0; i < s.ops.loads.size(); ++i) {
      const double fi = inputs_[i](t);
      if (fi != 0.0) F += fi * s.ops.loads[i];
    }
    solver.acceleration(F.data(), x.data(), v.data(), acc.data());
    y += C2_ * acc;
    if (a) *a = acc;
  }
  return y;
}

VectorXd Objective::tangent_output_at(const SecondOrderSolver& solver, const Derivative& d, double t, const VectorXd& x,
                                      const VectorXd& v, const VectorXd& a, const VectorXd& si, const VectorXd& svi) const {
  if (C1_.size() == 0) return C_ * si;
  VectorXd y = C_ * si + C1_ * svi;
  if (accelerations_) {
    // S̈ from the sensitivity equation M S̈ + D Ṡ + K S = −(∂M ü + ∂D u̇ + ∂K u − ∂b f).
    const int n = model_.ndof;
    VectorXd G = -(d.dM * a + d.dD * v + d.dK * x), acc(n);
    if (d.rank_one.w.size() == n) G -= (d.rank_one.d * d.rank_one.w.dot(v) + d.rank_one.k * d.rank_one.w.dot(x)) * d.rank_one.w;
    for (std::size_t k = 0; k < d.db.size(); ++k) {
      const double fk = inputs_[k](t);
      if (fk != 0.0) G += fk * d.db[k];
    }
    solver.acceleration(G.data(), si.data(), svi.data(), acc.data());
    y += C2_ * acc;
  }
  return y;
}

Trajectory Objective::forward(const SecondOrderSolver& solver, const Setup& s, double t_end) {
  const auto t0 = Clock::now();
  SolverSummary sum;
  Trajectory u = solver.solve(data_.t.front(), t_end, state_forcing(s), breakpoints_, &sum, StepAnchor::Start, s.initial.get());
  counters_.solver.Accumulate(sum);
  ++counters_.forward_solves;
  counters_.forward_seconds += since(t0);
  return u;
}

// The breakpoints in reversed time τ = T − t (the costates' runs), sorted.
std::vector<double> Objective::reversed_breakpoints() const {
  std::vector<double> out;
  for (double b : breakpoints_)
    if (b < T_) out.push_back(T_ - b);
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<double> Objective::union_grid(const std::vector<const std::vector<double>*>& sets, double t_end,
                                          bool samples) const {
  std::vector<double> g;
  for (const auto* s : sets) g.insert(g.end(), s->begin(), s->end());
  if (samples)
    g.insert(g.end(), data_.t.begin(), data_.t.end());
  else
    g.push_back(data_.t.front());
  g.push_back(t_end);
  sort_grid(g);
  const double t0 = data_.t.front();
  g.erase(std::remove_if(g.begin(), g.end(), [&](double t) { return t < t0 || t > t_end; }), g.end());
  return g;
}

void Objective::window_grid(const Trajectory& w, double t_end, std::vector<double>& grid) const {
  // The window's part of the global grid (its times ∪ the sample times ∪ {t_end}, within
  // [t0, t_end]): consecutive windows share their boundary, so their grids join into the global one.
  grid.clear();
  const double lo = std::max(data_.t.front(), w.t_begin()), hi = std::min(t_end, w.t_end());
  if (!(hi > lo)) return;
  for (double t : w.times())
    if (t >= lo && t <= hi) grid.push_back(t);
  for (auto it = std::lower_bound(data_.t.begin(), data_.t.end(), lo); it != data_.t.end() && *it <= hi; ++it)
    grid.push_back(*it);
  grid.push_back(lo);
  grid.push_back(hi);
  sort_grid(grid);
}

double Objective::misfit_window(const Setup& s, const SecondOrderSolver& solver, const Trajectory& w,
                                const Measurements& z_of, double t_end) const {
  const int n = model_.ndof, ns = data_.sensors();
  std::vector<double> grid;
  window_grid(w, t_end, grid);
  VectorXd x(n), v(n), z(ns);
  double J = 0.0;
  for_each_gauss_point(grid, [&](double t, double wt) {
    w.eval(t, x.data(), v.data());
    z_of.eval(t, z.data());
    const VectorXd r = output_at(s, solver, t, x, v) - z;
    double e = 0.0;
    for (int j = 0; j < ns; ++j) e += R_[static_cast<std::size_t>(j)] * r[j] * r[j];
    J += 0.5 * wt * e;
  });
  return J;
}

double Objective::misfit_against(const Setup& s, const SecondOrderSolver& solver, const Trajectory& u,
                                 const Measurements& z_of) const {
  return misfit_window(s, solver, u, z_of, T_);
}

void Objective::forward_windows(const SecondOrderSolver& solver, const Setup& s, double t_end,
                                const WindowedSink::Visit& visit) {
  const auto t0 = Clock::now();
  double inside = 0.0;
  WindowedSink sink(model_.ndof, kStreamWindow, [&](const Trajectory& w) {
    const auto tv = Clock::now();
    visit(w);
    inside += since(tv);
  });
  SolverSummary sum;
  solver.stream(data_.t.front(), t_end, state_forcing(s), breakpoints_, [&](const SecondOrderSolver::Point& pt) { sink(pt); },
                &sum, nullptr, std::numeric_limits<double>::infinity(), StepAnchor::Start, s.initial.get());
  sink.finish();
  counters_.solver.Accumulate(sum);
  ++counters_.forward_solves;
  counters_.forward_seconds += since(t0) - inside;
  counters_.quadrature_seconds += inside;
}

// Running per-sensor sums ∫ r² and ∫ z² from t0, reported at each sample time t_i they pass as the
// mean over sensors of m_k = (∫r² − σ_k² B_i)⁺ / (∫z² − σ_k² W_i) (MisfitProfile): with stated noise,
// what the residual holds beyond the noise's expected share plus two of its standard deviations,
// against the signal without its noise (docs/theory.md §7.3). A sensor whose record so far is noise
// alone (∫z² within the noise's share) limits no horizon: it has no phase to lose. Without stated
// noise (σ_k = 0) m_k = ∫r²/∫z².
struct Objective::ProfileSums {
  ProfileSums(const Measurements& d, const NoiseShare& n)
      : data(d), noise(n), rr(VectorXd::Zero(d.sensors())), zz(VectorXd::Zero(d.sensors())) {}
  void report(double t) {
    const auto ns = rr.size();
    while (next < data.t.size() && data.t[next] <= t) {
      double m = 0.0;
      for (Eigen::Index k = 0; k < ns; ++k) {
        if (noise.sigma2.size() == ns && noise.sigma2[k] > 0) {
          const double signal = zz[k] - noise.sigma2[k] * noise.W[next];
          const double beyond = std::max(0.0, rr[k] - noise.sigma2[k] * noise.B[next]);
          m += signal > 0 ? beyond / signal : 0.0;
        } else {
          m += zz[k] > 0 ? rr[k] / zz[k] : 0.0;
        }
      }
      prof.t.push_back(data.t[next]);
      prof.misfit.push_back(m / static_cast<double>(ns));
      ++next;
    }
  }
  const Measurements& data;
  const NoiseShare& noise;
  VectorXd rr, zz;
  std::size_t next = 1;  // next sample time to report
  MisfitProfile prof;
};

void Objective::noise_share() {
  const int ns = data_.sensors();
  bool any = false;
  noise_.sigma2 = VectorXd::Zero(ns);
  for (int k = 0; k < ns && k < static_cast<int>(options_.noise_std.size()); ++k) {
    const double sd = options_.noise_std[static_cast<std::size_t>(k)];
    if (sd > 0 && std::isfinite(sd)) {
      noise_.sigma2[k] = sd * sd;
      any = true;
    }
  }
  if (!any) {
    noise_ = {};
    return;
  }
  const double g = options_.noise_independent_fraction;
  const bool band = g < 1.0 && g > 0.0;
  if (band) {
    noise_.W.resize(data_.t.size());
    for (std::size_t i = 0; i < data_.t.size(); ++i) noise_.W[i] = data_.t[i] - data_.t.front();
  } else {
    noise_.W = data_.white_noise_integral_profile();
  }
  // Var ∫ñ² over [t0, t_i] taken in proportion to its mean (both grow with the interval count).
  const double W_all = noise_.W.back();
  const double V_all = data_.white_noise_integral_variance(data_.t.front(), data_.t.back()) / (band ? g : 1.0);
  noise_.B.resize(noise_.W.size());
  for (std::size_t i = 0; i < noise_.W.size(); ++i)
    noise_.B[i] = noise_.W[i] + 2.0 * std::sqrt(W_all > 0 ? V_all * noise_.W[i] / W_all : 0.0);
}

void Objective::profile_window(const Setup& s, const SecondOrderSolver& solver, const Trajectory& w,
                               ProfileSums& sums) const {
  const int n = model_.ndof, ns = data_.sensors();
  std::vector<double> grid;
  window_grid(w, data_.t.back(), grid);
  VectorXd x(n), v(n), z(ns);
  for_each_gauss_point(
      grid,
      [&](double t, double wt) {
        w.eval(t, x.data(), v.data());
        data_.eval(t, z.data());
        const VectorXd r = output_at(s, solver, t, x, v) - z;
        sums.rr += wt * r.cwiseAbs2();
        sums.zz += wt * z.cwiseAbs2();
      },
      [&](double t_end) { sums.report(t_end); });
}

double Objective::interpolation_misfit(const VectorXd& q) {
  Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  settle_initial_state(s, solver);
  // The whole record: the interpolant near T uses samples beyond it. The model's own samples first,
  // then the misfit against their interpolant: from one stored state when it fits the trajectory
  // budget, else from two streamed solves.
  const int n = model_.ndof, ns = data_.sensors();
  Measurements own{data_.names, data_.t, MatrixXd(static_cast<Eigen::Index>(data_.t.size()), ns)};
  const double points = (data_.t.back() - data_.t.front()) / (options_.solver.step > 0 ? options_.solver.step : 1e-300);
  if (!solver.can_resume() ||
      (options_.solver.step > 0 && points * model_.ndof * 3.0 * sizeof(double) <= options_.trajectory_bytes)) {
    const Trajectory u = forward(solver, s, data_.t.back());
    VectorXd x(n), v(n);
    for (std::size_t i = 0; i < data_.t.size(); ++i) {
      u.eval(data_.t[i], x.data(), v.data());
      own.z.row(static_cast<Eigen::Index>(i)) = output_at(s, solver, data_.t[i], x, v).transpose();
    }
    return misfit_against(s, solver, u, own);
  }
  const auto tf = Clock::now();
  SolverSummary sum;
  sample_streamed(solver, data_.t.front(), data_.t.back(), state_forcing(s), breakpoints_, data_.t,
                  [&](std::size_t k, const VectorXd& x, const VectorXd& v) {
                    own.z.row(static_cast<Eigen::Index>(k)) = output_at(s, solver, data_.t[k], x, v).transpose();
                  },
                  &sum, 256, s.initial.get());
  counters_.solver.Accumulate(sum);
  ++counters_.forward_solves;
  counters_.forward_seconds += since(tf);
  double J = 0.0;
  forward_windows(solver, s, data_.t.back(), [&](const Trajectory& w) { J += misfit_window(s, solver, w, own, T_); });
  return J;
}

Objective::MisfitProfile Objective::misfit_profile(const Setup& s, const SecondOrderSolver& solver,
                                                  const Trajectory& u) const {
  ProfileSums sums(data_, noise_);
  profile_window(s, solver, u, sums);
  return std::move(sums.prof);
}

double Objective::cost(const VectorXd& q) {
  // Streamed: the misfit accumulates window by window, so no O(steps) array is kept.
  Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  settle_initial_state(s, solver);
  double J = 0.0;
  forward_windows(solver, s, T_, [&](const Trajectory& w) { J += misfit_window(s, solver, w, data_, T_); });
  return J;
}

std::size_t Objective::checkpoint_spacing(const SecondOrderSolver& solver) const {
  if (!solver.can_resume()) return 0;
  const double t0 = data_.t.front();
  const double h = options_.solver.step > 0 ? options_.solver.step : (T_ - t0) / 2000.0;
  const double points = (T_ - t0) / h + 1.0 + 2.0 * static_cast<double>(breakpoints_.size());
  if (options_.checkpoint_points > 0) return static_cast<std::size_t>(options_.checkpoint_points);
  if (points * model_.ndof * 3.0 * sizeof(double) <= options_.trajectory_bytes) return 0;
  return static_cast<std::size_t>(std::max(2.0, std::ceil(std::sqrt(points / 3.0))));
}

bool Objective::cover_window(const Trajectory& W, CheckpointedState& state, std::vector<double>& grid,
                             std::vector<double>* steps, double& resolve_seconds) const {
  // The costate window [τa, τb] is t in [T − τb, T − τa] (within the data): the state there from
  // its checkpoints, and the grid of the window's times (in t), the state's and the samples' (in
  // `steps`, when asked: the same without the samples').
  const double ta = std::max(data_.t.front(), T_ - W.t_end()), tb = std::min(T_, T_ - W.t_begin());
  if (!(tb > ta)) return false;
  const auto tr = Clock::now();
  state.cover(ta, tb);
  resolve_seconds += since(tr);
  grid.clear();
  for (double tau : W.times()) grid.push_back(T_ - tau);
  state.times_in(ta, tb, grid);
  grid.push_back(ta);
  grid.push_back(tb);
  const auto finish = [&](std::vector<double>& g) {
    sort_grid(g);
    g.erase(std::remove_if(g.begin(), g.end(), [&](double t) { return t < ta || t > tb; }), g.end());
  };
  if (steps) {
    *steps = grid;
    finish(*steps);
  }
  for (double t : data_.t)
    if (t >= ta && t <= tb) grid.push_back(t);
  finish(grid);
  return true;
}

namespace {
// A checkpointed backward pass's counts: `costates` solves in `seconds`, of which `quadrature` in
// the quadrature and `resolve` re-solving the state's segments from checkpoints (a forward cost).
void count_checkpointed_pass(ObjectiveCounters& c, const SolverSummary& sum, const CheckpointedState& state, int costates,
                             double seconds, double quadrature, double resolve) {
  c.solver.Accumulate(sum);
  c.solver.Accumulate(state.summary());
  c.costate_solves += costates;
  ++c.checkpointed_passes;
  c.checkpoint_resolves += state.resolves();
  c.costate_seconds += seconds - quadrature - resolve;
  c.forward_seconds += resolve;
  c.quadrature_seconds += quadrature;
}
}  // namespace

// ---- The costates' sources (docs/theory.md §6.1–6.2) ----
// What forces the backward equations and what Eq. 25's quadrature takes from their solution. Two
// kinds: displacement sensors (one costate P, p = P(T − t)) and rate sensors (P and Y, p = P + Y' − μ).
// The backward passes below (state stored or checkpointed) take either.
class Objective::CostateSources {
 public:
  // y(t): the part of the residual the model gives (C u, or A₀u + A₁u̇ for rate sensors), from
  // wherever the pass holds the state or its outputs.
  using ModelPart = std::function<void(double t, VectorXd& y)>;
  virtual ~CostateSources() = default;
  // Costates solved together: 1 (P) or 2 (P and Y, stacked in a window).
  virtual int equations() const = 0;
  // Equation k's forcing at τ (k = 0: P's, 1: Y's).
  virtual void force(double tau, int k, double* F) = 0;
  // At the quadrature point t, with the state (x, v) and the costates' value c and derivative cd in
  // τ there (P, or P and Y stacked): the multiplier p, ṗ and (rate sensors) ü in a for Eq. 25.
  // Returns Σ R r² when the sources carry the residual, else 0.
  virtual double at(double t, const VectorXd& x, const VectorXd& v, const VectorXd& c, const VectorXd& cd, VectorXd& p,
                    VectorXd& pd, VectorXd& a) = 0;
  // Displacement sources (split_rule): J's share Σ R r² at t from the outputs alone, and `at`
  // gives the multiplier only (returns 0). Then the multiplier is the costate's interpolant, a
  // polynomial on every interval of the steps' union, and Eq. 25's n-long part takes a rule of its
  // own there (docs/theory.md §6.4).
  virtual bool split_rule() const { return false; }
  virtual double misfit(double) { return 0.0; }
  bool rates() const { return equations() == 2; }
};

// Displacement sensors: M P'' + D P' + K P = −CᵀR y(T − τ), y the model's outputs minus the data
// (`residual`), or the outputs alone (a Gauss–Newton product's tangent).
class Objective::DisplacementSources final : public CostateSources {
 public:
  DisplacementSources(const Objective& o, ModelPart part, bool residual)
      : o_(o), part_(std::move(part)), residual_(residual), y_(o.data_.sensors()), z_(o.data_.sensors()) {}
  int equations() const override { return 1; }
  void force(double tau, int, double* F) override {
    const double t = o_.T_ - tau;
    part_(t, y_);
    if (residual_) {
      o_.data_.eval(t, z_.data());
      y_ -= z_;
    }
    for (Eigen::Index j = 0; j < y_.size(); ++j) y_[j] *= -o_.R_[static_cast<std::size_t>(j)];
    Eigen::Map<VectorXd>(F, o_.model_.ndof).noalias() = o_.Cs_.transpose() * y_;
  }
  double at(double, const VectorXd&, const VectorXd&, const VectorXd& c, const VectorXd& cd, VectorXd& p, VectorXd& pd,
            VectorXd&) override {
    p = c;
    pd = -cd;  // ṗ(t) = −P'(T − t)
    return 0.0;
  }
  bool split_rule() const override { return true; }
  double misfit(double t) override {
    if (!residual_) return 0.0;
    part_(t, y_);
    o_.data_.eval(t, z_.data());
    y_ -= z_;
    double e = 0.0;
    for (Eigen::Index j = 0; j < y_.size(); ++j) e += o_.R_[static_cast<std::size_t>(j)] * y_[j] * y_[j];
    return e;
  }

 private:
  const Objective& o_;
  ModelPart part_;
  bool residual_;
  VectorXd y_, z_;
};

// Rate sensors (§6.1a): the sources w₀ = A₀ᵀ R r and w₁ = A₁ᵀ R r at t = T − τ (the left limit in t at
// a breakpoint), with the model's part A₀ u(t) + A₁ u̇(t), evaluated once per τ for both equations.
class Objective::RateSources final : public CostateSources {
 public:
  RateSources(const Objective& o, const RateTerms& rt, const SecondOrderSolver& solver,
              const SecondOrderSolver::Forcing& state_force, ModelPart part)
      : o_(o),
        rt_(rt),
        solver_(solver),
        state_force_(state_force),
        part_(std::move(part)),
        y_(o.data_.sensors()),
        z_(o.data_.sensors()),
        r_(o.data_.sensors()),
        F_(o.model_.ndof) {}
  int equations() const override { return 2; }
  void force(double tau, int k, double* F) override {
    sources_at(tau);
    Eigen::Map<VectorXd>(F, o_.model_.ndof) = k == 0 ? -w0_ : -w1_;
  }
  double at(double t, const VectorXd& x, const VectorXd& v, const VectorXd& c, const VectorXd& cd, VectorXd& p,
            VectorXd& pd, VectorXd& a) override {
    const int n = o_.model_.ndof;
    F_.setZero();
    state_force_(t, F_.data());
    solver_.acceleration(F_.data(), x.data(), v.data(), a.data());  // ü from the equation of motion
    o_.data_.eval(t, z_.data());
    VectorXd& r = r_;
    r.noalias() = o_.C_ * x;
    r.noalias() += o_.C1_ * v;
    if (o_.accelerations_) r.noalias() += o_.C2_ * a;
    r -= z_;
    double e = 0.0;
    for (Eigen::Index j = 0; j < r.size(); ++j) e += o_.R_[static_cast<std::size_t>(j)] * r[j] * r[j];
    // Multiplier of §6.1a: p = p₀ − ẏ − μ with ṗ₀(t) = −P'(T − t), ẏ(t) = −Y'(T − t).
    p = c.head(n) + cd.tail(n);
    pd = -cd.head(n);
    if (o_.accelerations_) {
      const Eigen::Map<const VectorXd> Rv(o_.R_.data(), r.size());
      p.noalias() -= rt_.MinvC2t * Rv.cwiseProduct(r);  // μ
    }
    return e;
  }

 private:
  // With an acceleration output r jumps where the input does. The stepper asks for the right limit
  // in τ at τ_b = T − t_b, which is the left limit in t (the signals are right-continuous).
  double time_of(double tau) const {
    const double t = o_.T_ - tau;
    for (double tb : o_.breakpoints_)
      if (std::abs(t - tb) <= 1e-12 * std::max(1.0, std::abs(tb)))
        return tau >= o_.T_ - tb ? std::nextafter(tb, -std::numeric_limits<double>::infinity()) : tb;
    return t;
  }
  void sources_at(double tau) {
    if (tau == tau_) return;
    tau_ = tau;
    const double t = time_of(tau);
    part_(t, y_);
    o_.data_.eval(t, z_.data());
    y_ -= z_;
    for (std::size_t i = 0; i < o_.inputs_.size(); ++i) {
      const double fi = o_.inputs_[i](t);
      if (fi != 0.0) y_ += fi * rt_.G.col(static_cast<Eigen::Index>(i));
    }
    for (Eigen::Index j = 0; j < y_.size(); ++j) y_[j] *= o_.R_[static_cast<std::size_t>(j)];
    w0_.noalias() = rt_.A0.transpose() * y_;
    w1_.noalias() = rt_.A1.transpose() * y_;
  }
  const Objective& o_;
  const RateTerms& rt_;
  const SecondOrderSolver& solver_;
  const SecondOrderSolver::Forcing& state_force_;
  ModelPart part_;
  VectorXd y_, z_, r_, F_, w0_, w1_;
  double tau_ = std::numeric_limits<double>::quiet_NaN();
};

Objective::RateTerms Objective::rate_terms(const Setup& s, const SecondOrderSolver& solver) const {
  const int n = model_.ndof, ns = data_.sensors();
  RateTerms rt;
  rt.MinvC2t = MatrixXd::Zero(n, ns);
  if (accelerations_) {
    const VectorXd zero = VectorXd::Zero(n);
    for (int k = 0; k < ns; ++k) {
      const VectorXd c = C2_.row(k).transpose();
      solver.acceleration(c.data(), zero.data(), zero.data(), rt.MinvC2t.col(k).data());
    }
  }
  rt.A0 = C_ - rt.MinvC2t.transpose() * s.ops.K;
  rt.A1 = C1_ - rt.MinvC2t.transpose() * s.ops.D;
  rt.G = MatrixXd::Zero(ns, static_cast<Eigen::Index>(s.ops.loads.size()));
  for (std::size_t i = 0; i < s.ops.loads.size(); ++i)
    rt.G.col(static_cast<Eigen::Index>(i)) = rt.MinvC2t.transpose() * s.ops.loads[i];
  return rt;
}

// ---- The backward passes: the costates in reversed time τ = T − t and Eq. 25's quadrature ----
double Objective::backward_checkpointed(const Setup& s, const SecondOrderSolver& solver, CostateSources& src,
                                        std::vector<Checkpoint> ckpts, std::size_t spacing, VectorXd& gc) {
  const int n = model_.ndof, m = src.equations();
  const double t0 = data_.t.front();
  const SecondOrderSolver::Forcing force = state_forcing(s);
  CheckpointedState state(solver, force, breakpoints_, T_, std::move(ckpts));
  const std::vector<double> bp_tau = reversed_breakpoints();
  double J = 0.0;
  VectorXd x(n), xv(n), a(n), p(n), pd(n), c(m * n), cd(m * n);
  std::vector<double> grid, steps;
  double quadrature = 0.0, resolve = 0.0;
  CoefficientQuadrature eq25(model_, src.rates(), CoefficientQuadrature::needed_coefficients(s.dcdq));
  // Each costate window [τa, τb] (P, or P and Y stacked) is t in [T − τb, T − τa]: the state there
  // from its checkpoints.
  WindowedSink windows(
      n, spacing,
      [&](const Trajectory& W) {
        if (!cover_window(W, state, grid, src.split_rule() ? &steps : nullptr, resolve)) return;
        const auto tq = Clock::now();
        const auto point = [&](double t, double wt) {
          state.eval(t, x.data(), xv.data());
          W.eval(T_ - t, c.data(), cd.data());
          J += 0.5 * wt * src.at(t, x, xv, c, cd, p, pd, a);
          eq25.add(wt, p, pd, x, xv, a);
          add_input_gradient(t, wt, p, gc);
        };
        if (src.split_rule()) {
          for_each_gauss_point(grid, [&](double t, double wt) { J += 0.5 * wt * src.misfit(t); });
          for_each_two_point(steps, point);
        } else {
          for_each_gauss_point(grid, point);
        }
        quadrature += since(tq);
      },
      m);
  const auto tc = Clock::now();
  SolverSummary sum;
  const SecondOrderSolver::Forcing g0 = [&](double tau, double* F) { src.force(tau, 0, F); };
  const bool boundary = s.initial && src.split_rule();
  VectorXd p_t0 = VectorXd::Zero(n);  // the multiplier at t0: P at the costate's last point
  const auto visit = [&](const SecondOrderSolver::Point& pt) {
    windows(pt);
    if (boundary) p_t0 = Eigen::Map<const VectorXd>(pt.x, n);
  };
  if (m == 1) {
    solver.stream(0.0, T_ - t0, g0, bp_tau, visit, &sum, nullptr, std::numeric_limits<double>::infinity(),
                  StepAnchor::End);
  } else {  // Y stepped with P on P's stages
    const SecondOrderSolver::TangentForcing g1 = [&](double tau, const double*, const double*, const double*,
                                                     double* F) { src.force(tau, 1, F); };
    solver.stream_tangent(0.0, T_ - t0, g0, 1, g1, T_ - t0, bp_tau, visit, &sum, StepAnchor::End);
  }
  windows.finish();
  eq25.contract(gc);
  if (boundary) add_initial_velocity_term(s, p_t0, gc);
  count_checkpointed_pass(counters_, sum, state, m, since(tc), quadrature, resolve);
  return J;
}

void Objective::costates_stored(const SecondOrderSolver& solver, CostateSources& src, Trajectory& P, Trajectory& Y) {
  const double t0 = data_.t.front();
  const std::vector<double> bp_tau = reversed_breakpoints();
  const auto tc = Clock::now();
  SolverSummary sum;
  const SecondOrderSolver::Forcing g0 = [&](double tau, double* F) { src.force(tau, 0, F); };
  if (src.equations() == 1) {
    P = solver.solve(0.0, T_ - t0, g0, bp_tau, &sum, StepAnchor::End);
    counters_.solver.Accumulate(sum);
  } else if (solver.has_tangent_solve()) {
    // Y stepped with P on P's stages, sharing the factorisations and the forcing evaluations.
    const SecondOrderSolver::TangentForcing g1 = [&](double tau, const double*, const double*, const double*,
                                                     double* F) { src.force(tau, 1, F); };
    auto sol = solver.solve_tangent(0.0, T_ - t0, g0, 1, g1, T_ - t0, bp_tau, &sum, StepAnchor::End);
    counters_.solver.Accumulate(sum);
    P = std::move(sol.state);
    Y = std::move(sol.tangents.front());
  } else {
    const SecondOrderSolver::Forcing g1 = [&](double tau, double* F) { src.force(tau, 1, F); };
    P = solver.solve(0.0, T_ - t0, g0, bp_tau, &sum, StepAnchor::End);
    counters_.solver.Accumulate(sum);
    Y = solver.solve(0.0, T_ - t0, g1, bp_tau, &sum, StepAnchor::End);
    counters_.solver.Accumulate(sum);
  }
  counters_.costate_solves += src.equations();
  counters_.costate_seconds += since(tc);
}

double Objective::backward_stored(const Setup& s, const SecondOrderSolver& solver, const Trajectory& u,
                                  CostateSources& src, const std::vector<double>& more_times, VectorXd& gc) {
  const std::vector<bool> needed = CoefficientQuadrature::needed_coefficients(s.dcdq);
  const int n = model_.ndof, m = src.equations();
  Trajectory P, Y;
  costates_stored(solver, src, P, Y);
  const auto tq = Clock::now();
  std::vector<double> ptimes, ytimes;
  ptimes.reserve(P.size());
  for (double tau : P.times()) ptimes.push_back(T_ - tau);
  if (m == 2)
    for (double tau : Y.times()) ytimes.push_back(T_ - tau);
  const auto grid = union_grid({&u.times(), &ptimes, &ytimes, &more_times}, T_);
  VectorXd x(n), v = VectorXd::Zero(n), a(n), p(n), pd(n), c(m * n), cd = VectorXd::Zero(m * n);
  double J = 0.0;
  CoefficientQuadrature eq25(model_, src.rates(), needed);
  // Displacement sources read x and the multiplier alone: v and ṗ are interpolated when Eq. 25 reads them.
  const bool v_read = m == 2 || eq25.reads_velocity(), pd_read = m == 2 || eq25.reads_multiplier_rate();
  const auto point = [&](double t, double wt) {
    u.eval(t, x.data(), v_read ? v.data() : nullptr);
    P.eval(T_ - t, c.data(), pd_read ? cd.data() : nullptr);
    if (m == 2) Y.eval(T_ - t, c.data() + n, cd.data() + n);
    J += 0.5 * wt * src.at(t, x, v, c, cd, p, pd, a);
    eq25.add(wt, p, pd, x, v, a);
    add_input_gradient(t, wt, p, gc);
  };
  if (src.split_rule()) {
    for_each_gauss_point(grid, [&](double t, double wt) { J += 0.5 * wt * src.misfit(t); });
    for_each_two_point(union_grid({&u.times(), &ptimes, &ytimes, &more_times}, T_, false), point);
  } else {
    for_each_gauss_point(grid, point);
  }
  eq25.contract(gc);
  if (s.initial && src.split_rule()) {
    P.eval(T_ - data_.t.front(), c.data(), nullptr);
    add_initial_velocity_term(s, c.head(n), gc);
  }
  counters_.quadrature_seconds += since(tq);
  return J;
}

double Objective::cost_and_gradient(const VectorXd& q, VectorXd& gradient) {
  Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  settle_initial_state(s, solver);
  VectorXd gc = VectorXd::Zero(model_.ncoef);
  const std::size_t L = checkpoint_spacing(solver);
  const double J = L > 0 ? gradient_checkpointed(s, solver, L, gc) : gradient_stored(s, solver, gc);
  gradient = s.dcdq.transpose() * gc;
  ++counters_.gradient_evaluations;
  last_gradient_ = {q, T_, J, gradient, MatrixXd()};
  return J;
}

double Objective::recalled_cost_and_gradient(const VectorXd& q, VectorXd& gradient) {
  MatrixXd none;
  if (double J = 0.0; last_gradient_.recall(q, T_, J, gradient, none)) return J;
  return cost_and_gradient(q, gradient);
}

double Objective::gradient_checkpointed(const Setup& s, const SecondOrderSolver& solver, std::size_t L, VectorXd& gc) {
  const bool rates = C1_.size() != 0;
  // Checkpointed (docs/theory.md §7.9): the forward run keeps its outputs and every L-th point.
  // With rate sensors the outputs are A₀u and A₁u̇ (each with its derivative, so that their
  // interpolants are those of the state's), from which the residual needs only f(t) and z(t).
  const int n = model_.ndof, ns = data_.sensors();
  RateTerms rt;
  if (rates) rt = rate_terms(s, solver);
  const auto tf = Clock::now();
  CheckpointRecorder ck(n, L);
  Trajectory out(rates ? 2 * ns : ns);
  VectorXd y(2 * ns), yd(2 * ns);
  const VectorXd none = VectorXd::Zero(2 * ns);
  SolverSummary sum;
  solver.stream(data_.t.front(), T_, state_forcing(s), breakpoints_,
                [&](const SecondOrderSolver::Point& pt) {
                  ck(pt);
                  if (!rates) {
                    push_outputs(Cs_, out, pt.t, pt.x, pt.v, pt.a);
                    return;
                  }
                  const Eigen::Map<const VectorXd> x(pt.x, n), v(pt.v, n), a(pt.a, n);
                  y.head(ns).noalias() = rt.A0 * x;
                  y.tail(ns).noalias() = rt.A1 * v;
                  yd.head(ns).noalias() = rt.A0 * v;
                  yd.tail(ns).noalias() = rt.A1 * a;
                  out.push(pt.t, y.data(), yd.data(), none.data());
                },
                &sum, nullptr, std::numeric_limits<double>::infinity(), StepAnchor::Start, s.initial.get());
  counters_.solver.Accumulate(sum);
  ++counters_.forward_solves;
  counters_.forward_seconds += since(tf);
  // The sources from the recorded outputs: the same numbers as C (or A₀, A₁) times the state's
  // interpolant.
  if (!rates) {
    DisplacementSources src(
        *this, [&](double t, VectorXd& yb) { out.eval(t, yb.data(), yd.data()); }, true);
    return backward_checkpointed(s, solver, src, std::move(ck.checkpoints()), L, gc);
  }
  const SecondOrderSolver::Forcing force = state_forcing(s);
  RateSources src(*this, rt, solver, force, [&](double t, VectorXd& yb) {
    out.eval(t, y.data(), yd.data());
    yb = y.head(ns) + y.tail(ns);
  });
  return backward_checkpointed(s, solver, src, std::move(ck.checkpoints()), L, gc);
}

// The gradient on a stored state: forward, then the backward pass with the sources read from it.
double Objective::gradient_stored(const Setup& s, const SecondOrderSolver& solver, VectorXd& gc) {
  const Trajectory u = forward(solver, s, T_);
  const int n = model_.ndof;
  VectorXd xb(n), vb(n);
  if (C1_.size() == 0) {
    // The sources read the outputs C u at the state's points, interpolated like u (the same numbers
    // as C times u's interpolant, a sensors-long interpolation per costate stage instead of an n-long one).
    Trajectory out(data_.sensors());
    out.reserve(u.size());
    for (std::size_t k = 0; k < u.size(); ++k)
      push_outputs(Cs_, out, u.times()[k], u.x(k).data(), u.v(k).data(), u.a(k).data());
    DisplacementSources src(
        *this, [&](double t, VectorXd& y) { out.eval(t, y.data(), vb.data()); }, true);
    return backward_stored(s, solver, u, src, {}, gc);
  }
  const SecondOrderSolver::Forcing force = state_forcing(s);
  const RateTerms rt = rate_terms(s, solver);
  RateSources src(*this, rt, solver, force, [&](double t, VectorXd& y) {
    u.eval(t, xb.data(), vb.data());
    y.noalias() = rt.A0 * xb;
    y.noalias() += rt.A1 * vb;
  });
  return backward_stored(s, solver, u, src, {}, gc);
}

// The input coefficients' share of Eq. 25 at a quadrature point: −wt f_i(t) pᵀ b_i (the operator
// terms' share is CoefficientQuadrature's).
void Objective::add_input_gradient(double t, double wt, const VectorXd& p, VectorXd& gc) const {
  for (std::size_t i = 0; i < model_.inputs.size(); ++i) {
    const int ci = model_.inputs[i].coefficient;
    if (ci >= 0) gc[ci] -= wt * inputs_[i](t) * p.dot(model_.inputs[i].vector);
  }
}

Objective::Derivative Objective::derivative(const Setup& s, int i) const { return derivative_along(s.dcdq.col(i)); }

Objective::Derivative Objective::derivative_along(const VectorXd& dcol) const {
  const int n = model_.ndof;
  // Constant terms (coefficient −1) do not enter the derivative.
  auto only_coef = [&](const std::vector<OperatorTerm>& terms) {
    SparseMatrix A(n, n);
    for (const auto& t : terms)
      if (t.coefficient >= 0 && dcol[t.coefficient] != 0.0) A += dcol[t.coefficient] * t.matrix;
    return A;
  };
  Derivative d;
  d.dM = only_coef(model_.mass);
  d.dD = only_coef(model_.damping);
  d.dK = only_coef(model_.stiffness);
  for (const auto& in : model_.inputs)
    d.db.push_back(in.coefficient >= 0 ? VectorXd(dcol[in.coefficient] * in.vector) : VectorXd(VectorXd::Zero(n)));
  return d;
}

Trajectory Objective::sensitivity(const SecondOrderSolver& solver, const Setup& s, const Trajectory& u, const Derivative& d,
                                  double t_end) const {
  const int n = model_.ndof;
  VectorXd x(n), v(n), a(n), Fe(n);
  SecondOrderSolver::Forcing f = [&](double t, double* F) {
    u.eval(t, x.data(), v.data());
    Fe.setZero();
    for (std::size_t k = 0; k < s.ops.loads.size(); ++k) Fe += inputs_[k](t) * s.ops.loads[k];
    solver.acceleration(Fe.data(), x.data(), v.data(), a.data());
    Eigen::Map<VectorXd> Fm(F, n);
    Fm = -(d.dM * a + d.dD * v + d.dK * x);
    if (d.rank_one.w.size() == n) Fm -= (d.rank_one.d * d.rank_one.w.dot(v) + d.rank_one.k * d.rank_one.w.dot(x)) * d.rank_one.w;
    for (std::size_t k = 0; k < d.db.size(); ++k) Fm += inputs_[k](t) * d.db[k];
  };
  return solver.solve(data_.t.front(), t_end, f, breakpoints_, nullptr);
}

int Objective::sensitivity_block(double t_end) const {
  const int P = size();
  const double t0 = data_.t.front();
  const double h = options_.solver.step > 0 ? options_.solver.step : (t_end - t0) / 2000.0;
  const double points = (t_end - t0) / h + 1.0 + 2.0 * static_cast<double>(breakpoints_.size());
  const double bytes = points * model_.ndof * 3.0 * sizeof(double);
  const double fit = std::floor(options_.sensitivity_block_bytes / std::max(bytes, 1.0));
  return static_cast<int>(std::max(1.0, std::min(static_cast<double>(P), fit)));
}

std::vector<Trajectory> Objective::solve_with_sensitivities(const SecondOrderSolver& solver, const Setup& s,
                                                            double state_end, double tangent_end, Trajectory& u,
                                                            int first, int count) {
  if (count < 0) count = size() - first;
  std::vector<Derivative> d;
  for (int i = first; i < first + count; ++i) d.push_back(derivative(s, i));
  return solve_tangents(solver, s, state_end, tangent_end, u, d);
}

SecondOrderSolver::TangentForcing Objective::tangent_forcing(const std::vector<Derivative>& d) const {
  // The nonzeros of ∂M, ∂D, ∂K per derivative, row by row: a sectional parameter touches a few
  // elements, so the rows are few where the sparse product would still visit every column. Row r
  // takes its ∂M terms (on ü), then its ∂D terms (on u̇), then its ∂K terms (on u), each in column
  // order: the order of the column-by-column sparse products ∂M ü, ∂D u̇, ∂K u, so G_r is the same
  // to the last bit, with one running value per row instead of a load and a store per nonzero and
  // no choice of operand per nonzero. The ∂b are copied too: the function does not refer to `d`.
  struct Row {
    int row;
    int m_end, d_end, k_end;  // its terms: [previous k_end, m_end) on ü, [m_end, d_end) on u̇, [d_end, k_end) on u
  };
  struct Lists {
    std::vector<std::vector<Row>> rows;
    std::vector<std::vector<int>> cols;
    std::vector<std::vector<double>> values;
    std::vector<std::vector<VectorXd>> db;
    std::vector<RankOneDirection> rank_one;
  };
  auto L = std::make_shared<Lists>();
  L->rows.resize(d.size());
  L->cols.resize(d.size());
  L->values.resize(d.size());
  const int n = model_.ndof;
  // Per row and operand, the nonzeros in column order (a column-major sparse matrix's order).
  std::vector<std::array<std::vector<std::pair<int, double>>, 3>> by_row(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < d.size(); ++i) {
    for (auto& row : by_row)
      for (auto& terms : row) terms.clear();
    const SparseMatrix* mats[3] = {&d[i].dM, &d[i].dD, &d[i].dK};
    for (int w = 0; w < 3; ++w)
      for (int k = 0; k < mats[w]->outerSize(); ++k)
        for (SparseMatrix::InnerIterator it(*mats[w], k); it; ++it)
          if (it.value() != 0.0)
            by_row[static_cast<std::size_t>(it.row())][static_cast<std::size_t>(w)].emplace_back(static_cast<int>(it.col()),
                                                                                                   it.value());
    for (int r = 0; r < n; ++r) {
      const auto& terms = by_row[static_cast<std::size_t>(r)];
      if (terms[0].empty() && terms[1].empty() && terms[2].empty()) continue;
      Row row{r, 0, 0, 0};
      int* ends[3] = {&row.m_end, &row.d_end, &row.k_end};
      for (int w = 0; w < 3; ++w) {
        for (const auto& [c, v] : terms[static_cast<std::size_t>(w)]) {
          L->cols[i].push_back(c);
          L->values[i].push_back(v);
        }
        *ends[w] = static_cast<int>(L->cols[i].size());
      }
      L->rows[i].push_back(row);
    }
    L->db.push_back(d[i].db);
    L->rank_one.push_back(d[i].rank_one);
  }
  // (The inputs' values go into this thread's scratch: copies of the function may run on two threads.)
  return [this, n, L](double t, const double* x, const double* v, const double* a, double* Gp) {
    thread_local std::vector<double> f;
    f.resize(inputs_.size());
    for (std::size_t k = 0; k < inputs_.size(); ++k) f[k] = inputs_[k](t);
    for (std::size_t i = 0; i < L->rows.size(); ++i) {
      double* Gi = Gp + i * static_cast<std::size_t>(n);
      const int* col = L->cols[i].data();
      const double* val = L->values[i].data();
      int e = 0;
      for (const Row& row : L->rows[i]) {
        double g = Gi[row.row];
        for (; e < row.m_end; ++e) g -= val[e] * a[col[e]];
        for (; e < row.d_end; ++e) g -= val[e] * v[col[e]];
        for (; e < row.k_end; ++e) g -= val[e] * x[col[e]];
        Gi[row.row] = g;
      }
      Eigen::Map<VectorXd> Gm(Gi, n);
      const std::vector<VectorXd>& dbi = L->db[i];
      for (std::size_t k = 0; k < f.size() && k < dbi.size(); ++k)
        if (f[k] != 0.0) Gm += f[k] * dbi[k];
      if (const RankOneDirection& r1 = L->rank_one[i]; r1.w.size() == n) {
        const Eigen::Map<const VectorXd> xm(x, n), vm(v, n);
        Gm -= (r1.d * r1.w.dot(vm) + r1.k * r1.w.dot(xm)) * r1.w;
      }
    }
  };
}

std::vector<Trajectory> Objective::solve_tangents(const SecondOrderSolver& solver, const Setup& s, double state_end,
                                                  double tangent_end, Trajectory& u, const std::vector<Derivative>& d) {
  const int count = static_cast<int>(d.size());
  const auto ts = Clock::now();
  std::vector<Trajectory> S;
  if (solver.has_tangent_solve()) {
    const SecondOrderSolver::TangentForcing G = tangent_forcing(d);
    SolverSummary sum;
    const auto start = run_start(s, d);
    auto sol = solver.solve_tangent(data_.t.front(), state_end, state_forcing(s), count, G, tangent_end, breakpoints_, &sum,
                                    StepAnchor::Start, start.get());
    counters_.solver.Accumulate(sum);
    ++counters_.forward_solves;
    u = std::move(sol.state);
    S = std::move(sol.tangents);
  } else {
    u = forward(solver, s, state_end);
    for (const Derivative& di : d) S.push_back(sensitivity(solver, s, u, di, tangent_end));
  }
  counters_.sensitivity_solves += count;
  counters_.sensitivity_seconds += since(ts);
  return S;
}

double Objective::gauss_newton(const VectorXd& q, VectorXd& gradient, MatrixXd& H, MisfitProfile* profile) {
  if (double J = 0.0; !profile && last_gn_.recall(q, T_, J, gradient, H)) return J;
  last_gn_ = {};
  const double J = gauss_newton_solve(q, gradient, H, profile);
  if (!profile) last_gn_ = {q, T_, J, gradient, H};
  return J;
}

double Objective::step_matrix_step() const {
  const SolverOptions& so = options_.solver;
  if (so.integrator != SolverOptions::Integrator::Esdirk || !(so.step > 0.0) || !(options_.step_matrix_coarsening > 1.0))
    return so.step;
  const double sample = (data_.t.back() - data_.t.front()) / static_cast<double>(data_.t.size() - 1);
  return std::max(so.step, std::min(options_.step_matrix_coarsening * so.step, sample));
}

bool Objective::has_separate_step_matrix() const { return step_matrix_step() > options_.solver.step; }

void Objective::step_matrix(const VectorXd& q, MatrixXd& H) {
  VectorXd g;
  if (!has_separate_step_matrix()) {
    gauss_newton(q, g, H);
    return;
  }
  if (!step_matrix_) {
    ObjectiveOptions o = options_;
    o.solver.step = step_matrix_step();
    o.step_matrix_coarsening = 1.0;
    step_matrix_ = std::make_unique<Objective>(model_, params_, inputs_, data_, o);
  }
  step_matrix_->set_horizon(T_);
  step_matrix_->reset_counters();
  try {
    step_matrix_->gauss_newton(q, g, H);  // (its last evaluation kept: the same q again costs nothing)
  } catch (const std::exception& e) {
    if (!point_failure(e)) throw;
    // The longer step fails where the model's may not (an extreme trial point): the model's own.
    counters_.Accumulate(step_matrix_->counters());
    gauss_newton(q, g, H);
    return;
  }
  step_matrix_->kept_ = {};  // (its output sensitivities serve nothing: the matrix is for steps alone)
  counters_.Accumulate(step_matrix_->counters());
}

double Objective::gradient_and_step_matrix(const VectorXd& q, VectorXd& gradient, MatrixXd& H) {
  if (!has_separate_step_matrix()) return gauss_newton(q, gradient, H);
  if (double J = 0.0; last_step_.recall(q, T_, J, gradient, H)) return J;
  last_step_ = {};
  const double J = recalled_cost_and_gradient(q, gradient);
  step_matrix(q, H);
  last_step_ = {q, T_, J, gradient, H};
  return J;
}

double Objective::gauss_newton_solve(const VectorXd& q, VectorXd& gradient, MatrixXd& H, MisfitProfile* profile) {
  Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  settle_initial_state(s, solver);
  const int P = size(), ns = data_.sensors();
  const double state_end = profile ? data_.t.back() : T_;
  if (estimates_initial_state()) return gauss_newton_with_start(s, solver, state_end, gradient, H, profile);
  if (solver.has_tangent_solve()) {
    kept_ = {};
    MatrixXd G;
    const bool keep = T_ >= data_.t.back() && keeps_sensitivities();
    if (keep) G.resize(static_cast<Eigen::Index>(data_.t.size()) * ns, P);
    const double J = gauss_newton_streamed(s, solver, state_end, gradient, H, profile, keep ? &G : nullptr);
    if (keep) kept_ = {q, std::move(G)};
    return J;
  }
  return gauss_newton_blocked(s, solver, state_end, gradient, H, profile);
}

double Objective::gauss_newton_with_start(const Setup& s, const SecondOrderSolver& solver, double state_end, VectorXd& gradient,
                                          MatrixXd& H, MisfitProfile* profile) {
  // The parameters' tangents and the initial state's, from the settled start; then the Schur
  // complement: g and H of the parameters with the initial state's coefficients profiled out.
  const int P = size();
  kept_ = {};
  std::vector<Derivative> d;
  for (int i = 0; i < P; ++i) d.push_back(derivative(s, i));
  for (Derivative& di : initial_state_derivatives()) d.push_back(std::move(di));
  VectorXd g_all;
  MatrixXd H_all;
  const double J = gauss_newton_streamed(s, solver, state_end, g_all, H_all, profile, nullptr, &d);
  const int m = static_cast<int>(d.size()) - P;
  const MatrixXd Hpa = H_all.topRightCorner(P, m);
  const MatrixXd X = pseudo_solve(H_all.bottomRightCorner(m, m), Hpa.transpose());
  H = H_all.topLeftCorner(P, P) - Hpa * X;
  H = 0.5 * (H + H.transpose()).eval();
  gradient = g_all.head(P) - X.transpose() * g_all.tail(m);
  return J;
}

double Objective::gauss_newton_blocked(const Setup& s, const SecondOrderSolver& solver, double state_end, VectorXd& gradient,
                                       MatrixXd& H, MisfitProfile* profile) {
  const int P = size(), n = model_.ndof, ns = data_.sensors();
  // Without a tangent stepper: the tangents in blocks of at most sensitivity_block() trajectories,
  // the state re-solved with each block; their outputs C S at the quadrature points are kept
  // (quadrature points × sensors × P numbers), not the trajectories.
  const int B = sensitivity_block(state_end);
  Trajectory u;
  std::vector<double> grid;
  MatrixXd CSall;  // row (point · ns + sensor), column parameter
  VectorXd x(n), v(n), a(n), si(n), sv(n);
  for (int first = 0; first < P; first += B) {
    const int count = std::min(B, P - first);
    const std::vector<Trajectory> S = solve_with_sensitivities(solver, s, state_end, T_, u, first, count);
    const auto tq = Clock::now();
    if (first == 0) {
      grid = union_grid({&u.times()}, T_);
      CSall.resize(static_cast<Eigen::Index>(3 * (grid.size() - 1) * static_cast<std::size_t>(ns)), P);
    }
    std::vector<Derivative> d;
    if (accelerations_)
      for (int i = first; i < first + count; ++i) d.push_back(derivative(s, i));
    Eigen::Index row = 0;
    for_each_gauss_point(grid, [&](double t, double) {
      u.eval(t, x.data(), v.data());
      if (accelerations_) output_at(s, solver, t, x, v, &a);
      for (int i = 0; i < count; ++i) {
        S[static_cast<std::size_t>(i)].eval(t, si.data(), sv.data());
        CSall.block(row, first + i, ns, 1) = accelerations_
                                                 ? tangent_output_at(solver, d[static_cast<std::size_t>(i)], t, x, v, a, si, sv)
                                                 : tangent_output_at(solver, Derivative{}, t, x, v, a, si, sv);
      }
      row += ns;
    });
    counters_.quadrature_seconds += since(tq);
  }

  const auto tq = Clock::now();
  VectorXd z(ns);
  gradient = VectorXd::Zero(P);
  H = MatrixXd::Zero(P, P);
  const Eigen::Map<const VectorXd> Rv(R_.data(), ns);
  double J = 0.0;
  GaussNewtonSums sums(P, Rv, J, gradient, H);
  Eigen::Index row = 0;
  for_each_gauss_point(grid, [&](double t, double wt) {
    u.eval(t, x.data(), v.data());
    data_.eval(t, z.data());
    const VectorXd r = output_at(s, solver, t, x, v, &a) - z;
    sums.add(wt, r, CSall.middleRows(row, ns));
    row += ns;
  });
  sums.finish();
  if (profile) *profile = misfit_profile(s, solver, u);
  counters_.quadrature_seconds += since(tq);
  return J;
}

void Objective::interval_cuts(double a, double b, std::size_t& next, std::vector<double>& cuts) const {
  cuts.assign(1, a);
  while (next < data_.t.size() && data_.t[next] <= a) ++next;
  for (std::size_t k = next; k < data_.t.size() && data_.t[k] < b; ++k) cuts.push_back(data_.t[k]);
  cuts.push_back(b);
}

void Objective::point_outputs(int cols, const double* x, const double* v, const double* a, MatrixXd& Yx,
                              MatrixXd& Yv) const {
  const auto n = static_cast<Eigen::Index>(model_.ndof);
  const bool rate_rows = C1_.size() > 0;
  for (int j = 0; j < cols; ++j) {
    const auto off = static_cast<std::ptrdiff_t>(j) * n;
    const Eigen::Map<const VectorXd> xj(x + off, n), vj(v + off, n), aj(a + off, n);
    Yx.col(j).noalias() = Cs_ * xj;
    Yv.col(j).noalias() = Cs_ * vj;
    if (rate_rows) {
      Yx.col(j).noalias() += C1_ * vj;
      Yv.col(j).noalias() += C1_ * aj;
    }
  }
}

bool Objective::splits_sweep(double state_end, int P) const {
  if (P < 2 || accelerations_ || options_.sweep_threads == 1 || !(options_.solver.step > 0)) return false;
  if (options_.sweep_threads == 0 && std::thread::hardware_concurrency() < 2) return false;
  // The recorded outputs of both groups: points × sensors × (P + 2 state columns) × (Yx, Yv).
  const double points = (state_end - data_.t.front()) / options_.solver.step + static_cast<double>(breakpoints_.size()) + 2.0;
  const double bytes = points * data_.sensors() * (P + 2.0) * 2.0 * 8.0;
  return bytes <= options_.sensitivity_block_bytes;
}

void Objective::stream_outputs(const Setup& s, const SecondOrderSolver& solver, double state_end, double tangent_end,
                               const std::vector<Derivative>& d, const SecondOrderSolver::Sink& visit_state,
                               const OutputVisit& at, SolverSummary& sum) const {
  const int P = static_cast<int>(d.size()), ns = data_.sensors(), m = 1 + P;
  const double t0 = data_.t.front();
  if (!splits_sweep(state_end, P)) {
    const SecondOrderSolver::TangentForcing Gf = tangent_forcing(d);
    const auto start = run_start(s, d);
    MatrixXd Yx(ns, m), Yv(ns, m);
    solver.stream_tangent(t0, state_end, state_forcing(s), P, Gf, tangent_end, breakpoints_,
                          [&](const SecondOrderSolver::Point& pt) {
                            if (visit_state) visit_state(pt);
                            if (pt.columns == m) point_outputs(m, pt.x, pt.v, pt.a, Yx, Yv);
                            at(pt.t, pt.columns == m ? m : 1, Yx, Yv);
                          },
                          &sum, StepAnchor::Start, start.get());
    return;
  }
  // Two groups of tangents, [0, PA) here and [PA, P) on a worker, each with its own state column
  // (stepped alike: the state's stages do not depend on the tangents) and its own solver. Every
  // point's outputs are recorded; the two records are walked together once both are done.
  struct Record {
    int first = 0, count = 0;
    std::vector<double> t;
    std::vector<int> cols;
    std::vector<double> y;  // per point with tangents: Yx then Yv, sensors × (1 + count) each
    SolverSummary sum;
  };
  const int PA = (P + 1) / 2;
  Record ra, rb;
  ra.count = PA;
  rb.first = PA;
  rb.count = P - PA;
  auto run = [&](const SecondOrderSolver& sv, Record& r, const SecondOrderSolver::Sink* also) {
    const std::vector<Derivative> dg(d.begin() + r.first, d.begin() + r.first + r.count);
    const SecondOrderSolver::TangentForcing Gf = tangent_forcing(dg);
    const auto start = run_start(s, dg);
    const int mg = 1 + r.count;
    MatrixXd Yx(ns, mg), Yv(ns, mg);
    sv.stream_tangent(t0, state_end, state_forcing(s), r.count, Gf, tangent_end, breakpoints_,
                      [&](const SecondOrderSolver::Point& pt) {
                        if (also && *also) (*also)(pt);
                        r.t.push_back(pt.t);
                        r.cols.push_back(pt.columns);
                        if (pt.columns != mg) return;
                        point_outputs(mg, pt.x, pt.v, pt.a, Yx, Yv);
                        r.y.insert(r.y.end(), Yx.data(), Yx.data() + Yx.size());
                        r.y.insert(r.y.end(), Yv.data(), Yv.data() + Yv.size());
                      },
                      &r.sum, StepAnchor::Start, start.get());
  };
  std::exception_ptr worker_error;
  std::thread worker([&] {
    try {
      const SecondOrderSolver own(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
      run(own, rb, nullptr);
    } catch (...) {
      worker_error = std::current_exception();
    }
  });
  try {
    run(solver, ra, &visit_state);
  } catch (...) {
    worker.join();
    throw;
  }
  worker.join();
  if (worker_error) std::rethrow_exception(worker_error);
  // The work of both (solves, factorisations, forcings); the steps and the wall time once: the two
  // step one grid side by side, so a run's step count does not depend on how many threads stepped it.
  sum.Accumulate(ra.sum);
  rb.sum.steps = 0;
  rb.sum.wall_seconds = 0.0;
  sum.Accumulate(rb.sum);
  if (rb.t != ra.t) throw std::logic_error("stream_outputs: the two tangent groups did not step alike");
  MatrixXd Yx(ns, m), Yv(ns, m);
  const auto block = static_cast<std::size_t>(ns);
  std::size_t ia = 0, ib = 0;  // offsets into ra.y, rb.y
  for (std::size_t k = 0; k < ra.t.size(); ++k) {
    const bool on = ra.cols[k] == 1 + ra.count;
    if (on != (rb.cols[k] == 1 + rb.count)) throw std::logic_error("stream_outputs: the tangent groups stopped apart");
    if (on) {
      const auto na = block * static_cast<std::size_t>(1 + ra.count), nb = block * static_cast<std::size_t>(1 + rb.count);
      const Eigen::Map<const MatrixXd> ax(ra.y.data() + ia, ns, 1 + ra.count), av(ra.y.data() + ia + na, ns, 1 + ra.count);
      const Eigen::Map<const MatrixXd> bx(rb.y.data() + ib, ns, 1 + rb.count), bv(rb.y.data() + ib + nb, ns, 1 + rb.count);
      Yx.leftCols(1 + ra.count) = ax;
      Yv.leftCols(1 + ra.count) = av;
      Yx.rightCols(rb.count) = bx.rightCols(rb.count);
      Yv.rightCols(rb.count) = bv.rightCols(rb.count);
      ia += 2 * na;
      ib += 2 * nb;
    }
    at(ra.t[k], on ? m : 1, Yx, Yv);
  }
}

bool Objective::keeps_sensitivities() const {
  const double bytes = 8.0 * static_cast<double>(data_.t.size()) * data_.sensors() * size();
  return !accelerations_ && bytes <= options_.sensitivity_block_bytes;
}

// One streamed Gauss–Newton pass's running quadrature: the sums, the last recorded point's time,
// the first data time not below it, and the time spent integrating.
struct Objective::StreamPass {
  StreamPass(int P, const Eigen::Map<const VectorXd>& R, double& J, VectorXd& gradient, MatrixXd& H, double t0, double T)
      : gn(P, R, J, gradient, H), t0(t0), T(T), m(1 + P) {}
  GaussNewtonSums gn;
  const double t0, T;
  const int m;  // columns: the state and the P tangents
  double t_prev = 0.0, quadrature = 0.0;
  bool have_prev = false;
  std::size_t next_data = 0;
  std::vector<double> cuts;
  // The interval from the last point to one at t1 (with `cols` columns) clipped to [t0, T]: true,
  // with its cuts at the data times, when there is one to integrate.
  bool interval_to(const Objective& o, double t1, int cols) {
    const double a_end = std::max(t_prev, t0), b_end = std::min(t1, T);
    if (!(have_prev && t1 > t_prev && b_end > a_end)) return false;
    if (cols < m) throw std::logic_error("gauss_newton: the tangents stopped before the horizon");
    o.interval_cuts(a_end, b_end, next_data, cuts);
    return true;
  }
};

double Objective::gauss_newton_streamed(const Setup& s, const SecondOrderSolver& solver, double state_end,
                                        VectorXd& gradient, MatrixXd& H, MisfitProfile* profile, MatrixXd* sample_rows,
                                        const std::vector<Derivative>* derivs) {
  // All P tangents stepped with the state in one pass (docs/theory.md §7.9); between consecutive
  // recorded points the union grid's intervals (the points' and the data's times, clipped to
  // [t0, T]) are integrated at once, with x, v and the tangents interpolated as Trajectory::eval
  // does: g, H and J accumulate on the fly, so memory is O(P · DOF + P²) whatever the record's
  // length, and the state is stored only for the misfit profile.
  std::vector<Derivative> d;
  if (derivs) d = *derivs;
  else for (int i = 0; i < size(); ++i) d.push_back(derivative(s, i));
  const int P = static_cast<int>(d.size()), n = model_.ndof, ns = data_.sensors();
  const auto ts = Clock::now();
  const Eigen::Map<const VectorXd> Rv(R_.data(), ns);
  gradient = VectorXd::Zero(P);
  H = MatrixXd::Zero(P, P);
  double J = 0.0;
  StreamPass pass(P, Rv, J, gradient, H, data_.t.front(), T_);
  // The misfit profile (over the whole record) from the state's column in windows.
  std::unique_ptr<ProfileSums> sums;
  std::unique_ptr<WindowedSink> profile_sink;
  if (profile) {
    sums = std::make_unique<ProfileSums>(data_, noise_);
    profile_sink = std::make_unique<WindowedSink>(n, kStreamWindow, [&](const Trajectory& w) {
      const auto tp = Clock::now();
      profile_window(s, solver, w, *sums);
      pass.quadrature += since(tp);
    });
  }
  SolverSummary sum;
  if (!accelerations_) {
    SecondOrderSolver::Sink state_visit;
    if (profile_sink) state_visit = [&](const SecondOrderSolver::Point& pt) { (*profile_sink)(pt); };
    stream_output_pass(s, solver, state_end, d, state_visit, sample_rows, pass, sum);
  } else {
    stream_state_pass(s, solver, state_end, d, profile_sink.get(), pass, sum);
  }
  const auto tf = Clock::now();
  pass.gn.finish();
  pass.quadrature += since(tf);
  if (profile) {
    profile_sink->finish();  // (its windows' time is in `quadrature`)
    *profile = std::move(sums->prof);
  }
  counters_.solver.Accumulate(sum);
  ++counters_.forward_solves;
  counters_.sensitivity_solves += P;
  counters_.sensitivity_seconds += since(ts) - pass.quadrature;
  counters_.quadrature_seconds += pass.quadrature;
  return J;
}

void Objective::stream_output_pass(const Setup& s, const SecondOrderSolver& solver, double state_end,
                                   const std::vector<Derivative>& d, const SecondOrderSolver::Sink& state_visit,
                                   MatrixXd* sample_rows, StreamPass& pass, SolverSummary& sum) const {
  // Without acceleration sensors the outputs are C x + C₁ v of every column, linear in the
  // recorded points: the Hermite interpolation is done on the outputs of the two points (sensors ×
  // columns) instead of on the states (DOFs × columns). Yx = C X + C₁ V, Yv = C V + C₁ A per point
  // (stream_outputs: on one thread or two).
  const int ns = data_.sensors(), m = pass.m, P = m - 1;
  MatrixXd Yx0(ns, m), Yv0(ns, m), Ys(ns, m), Ykeep(ns, m);
  VectorXd z(ns);
  std::size_t next_sample = 0;  // the first sample not yet in sample_rows
  const auto at = [&](double t1, int cols, const MatrixXd& Yx1, const MatrixXd& Yv1) {
    if (sample_rows && cols == m)
      sample_output_rows(data_.t, next_sample, pass.have_prev, pass.t_prev, t1, Yx0, Yv0, Yx1, Yv1, Ykeep, *sample_rows);
    if (pass.interval_to(*this, t1, cols)) {
      const auto tq = Clock::now();
      const double t_prev = pass.t_prev, h = t1 - t_prev;
      for_each_gauss_point(pass.cuts, [&](double t, double wt) {
        const auto [h00, h10, h01, h11] = hermite_weights(t, t_prev, h);
        Ys = h00 * Yx0 + h10 * Yv0 + h01 * Yx1 + h11 * Yv1;
        data_.eval(t, z.data());
        const VectorXd r = Ys.col(0) - z;
        pass.gn.add(wt, r, Ys.rightCols(P));
      });
      pass.quadrature += since(tq);
    }
    // This point's outputs are the next interval's left end (beyond the horizon, where the
    // tangents have stopped, nothing more is integrated).
    if (cols == m) {
      Yx0 = Yx1;
      Yv0 = Yv1;
    }
    pass.t_prev = t1;
    pass.have_prev = true;
  };
  stream_outputs(s, solver, state_end, T_, d, state_visit, at, sum);
}

void Objective::stream_state_pass(const Setup& s, const SecondOrderSolver& solver, double state_end,
                                  const std::vector<Derivative>& d, WindowedSink* profile_sink, StreamPass& pass,
                                  SolverSummary& sum) const {
  // With acceleration sensors an output needs the state's acceleration: the states (DOFs × columns)
  // are interpolated and each tangent's output taken from them.
  const int n = model_.ndof, ns = data_.sensors(), m = pass.m, P = m - 1;
  MatrixXd X0(n, m), V0(n, m), A0(n, m), Xs(n, m), Vs(n, m), CS(ns, P);
  VectorXd x(n), v(n), a(n), si(n), svi(n), z(ns);
  const SecondOrderSolver::TangentForcing Gf = tangent_forcing(d);
  auto visit = [&](const SecondOrderSolver::Point& pt) {
    if (profile_sink) (*profile_sink)(pt);
    const int cols = pt.columns;
    const Eigen::Map<const MatrixXd> X1(pt.x, n, cols), V1(pt.v, n, cols), A1(pt.a, n, cols);
    if (pass.interval_to(*this, pt.t, cols)) {
      const auto tq = Clock::now();
      const double t_prev = pass.t_prev, h = pt.t - t_prev;
      for_each_gauss_point(pass.cuts, [&](double t, double wt) {
        const auto [h00, h10, h01, h11] = hermite_weights(t, t_prev, h);
        Xs = h00 * X0 + h10 * V0 + h01 * X1 + h11 * V1;
        Vs = h00 * V0 + h10 * A0 + h01 * V1 + h11 * A1;
        x = Xs.col(0);
        v = Vs.col(0);
        data_.eval(t, z.data());
        const VectorXd r = output_at(s, solver, t, x, v, &a) - z;
        for (int i = 0; i < P; ++i) {
          si = Xs.col(1 + i);
          svi = Vs.col(1 + i);
          CS.col(i) = tangent_output_at(solver, d[static_cast<std::size_t>(i)], t, x, v, a, si, svi);
        }
        pass.gn.add(wt, r, CS);
      });
      pass.quadrature += since(tq);
    }
    if (cols == m) {
      X0 = X1;
      V0 = V1;
      A0 = A1;
    } else {  // the tangents have stopped (beyond the horizon): only the state moves on
      X0.col(0) = X1.col(0);
      V0.col(0) = V1.col(0);
      A0.col(0) = A1.col(0);
    }
    pass.t_prev = pt.t;
    pass.have_prev = true;
  };
  const auto start = run_start(s, d);
  solver.stream_tangent(data_.t.front(), state_end, state_forcing(s), P, Gf, T_, breakpoints_, visit, &sum, StepAnchor::Start,
                        start.get());
}

Objective::MisfitProfile Objective::misfit_profile(const VectorXd& q) {
  Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  settle_initial_state(s, solver);
  ProfileSums sums(data_, noise_);
  forward_windows(solver, s, data_.t.back(), [&](const Trajectory& w) { profile_window(s, solver, w, sums); });
  return std::move(sums.prof);
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
  Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  settle_initial_state(s, solver);
  // Streamed: only the outputs at the sample times are kept (the fit test predicts on a finer mesh
  // and step, whose whole state would be the largest array of the run).
  const auto t0 = Clock::now();
  MatrixXd Y(static_cast<Eigen::Index>(data_.t.size()), data_.sensors());
  SolverSummary sum;
  sample_streamed(solver, data_.t.front(), data_.t.back(), state_forcing(s), breakpoints_, data_.t,
                  [&](std::size_t k, const VectorXd& x, const VectorXd& v) {
                    Y.row(static_cast<Eigen::Index>(k)) = output_at(s, solver, data_.t[k], x, v).transpose();
                  },
                  &sum, 256, s.initial.get());
  counters_.solver.Accumulate(sum);
  ++counters_.forward_solves;
  counters_.forward_seconds += since(t0);
  return Y;
}

MatrixXd Objective::output_sensitivities(const VectorXd& q) {
  if (kept_.q.size() == q.size() && kept_.q == q) return kept_.G;
  Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  settle_initial_state(s, solver);
  const int n = model_.ndof, ns = data_.sensors();
  const double t_end = data_.t.back();
  VectorXd x(n), v(n), a(n), ux(n), uv(n);
  if (solver.has_tangent_solve()) {
    // Streamed (docs/theory.md §7.9): all P tangents stepped with the state in one pass, the
    // outputs at the sample times interpolated between consecutive points as Trajectory::eval
    // does; memory O(P · DOF + samples · sensors · P), nothing O(steps). With an estimated initial
    // state its 2m tangents too, and the parameters' columns projected off theirs.
    std::vector<Derivative> d;
    for (int i = 0; i < size(); ++i) d.push_back(derivative(s, i));
    if (estimates_initial_state())
      for (Derivative& di : initial_state_derivatives()) d.push_back(std::move(di));
    return streamed_output_sensitivities(s, solver, d, size());
  }
  // Without a tangent stepper: in blocks (as gauss_newton), memory O(block · steps · DOF + samples · sensors · P).
  const int P = size();
  MatrixXd G(static_cast<Eigen::Index>(data_.t.size()) * ns, P);
  const int B = sensitivity_block(t_end);
  for (int first = 0; first < P; first += B) {
    const int count = std::min(B, P - first);
    Trajectory u;
    const std::vector<Trajectory> S = solve_with_sensitivities(solver, s, t_end, t_end, u, first, count);
    for (int i = 0; i < count; ++i) {
      const Derivative d = accelerations_ ? derivative(s, first + i) : Derivative{};
      for (std::size_t k = 0; k < data_.t.size(); ++k) {
        const double t = data_.t[k];
        S[static_cast<std::size_t>(i)].eval(t, x.data(), v.data());
        if (accelerations_) {
          u.eval(t, ux.data(), uv.data());
          output_at(s, solver, t, ux, uv, &a);
        }
        G.block(static_cast<Eigen::Index>(k) * ns, first + i, ns, 1) = tangent_output_at(solver, d, t, ux, uv, a, x, v);
      }
    }
  }
  return G;
}

MatrixXd Objective::streamed_output_sensitivities(const Setup& s, const SecondOrderSolver& solver,
                                                  const std::vector<Derivative>& d, int leading) {
  const int n = model_.ndof, ns = data_.sensors();
  const double t_end = data_.t.back();
  VectorXd x(n), v(n), a(n), ux(n), uv(n);
  const auto ts = Clock::now();
  const int P = static_cast<int>(d.size());
  MatrixXd G(static_cast<Eigen::Index>(data_.t.size()) * ns, P);
  const int m = 1 + P;
  double t_prev = 0.0;
  bool have_prev = false;
  std::size_t next = 0;
  SolverSummary sum;
  if (!accelerations_) {
    // In output space, as the Gauss–Newton sweep (sample_output_rows), on one thread or two.
    MatrixXd Yx0(ns, m), Yv0(ns, m), Ys(ns, m);
    stream_outputs(s, solver, t_end, t_end, d, nullptr,
                   [&](double t1, int cols, const MatrixXd& Yx1, const MatrixXd& Yv1) {
                     if (cols < m) throw std::logic_error("output_sensitivities: the tangents stopped early");
                     sample_output_rows(data_.t, next, have_prev, t_prev, t1, Yx0, Yv0, Yx1, Yv1, Ys, G);
                     Yx0 = Yx1;
                     Yv0 = Yv1;
                     t_prev = t1;
                     have_prev = true;
                   },
                   sum);
    counters_.solver.Accumulate(sum);
    ++counters_.forward_solves;
    counters_.sensitivity_solves += P;
    counters_.sensitivity_seconds += since(ts);
    return project_initial_state(G, leading);
  }
  const SecondOrderSolver::TangentForcing Gf = tangent_forcing(d);
  MatrixXd X0(n, m), V0(n, m), A0(n, m), Xs(n, m), Vs(n, m);
  auto visit = [&](const SecondOrderSolver::Point& pt) {
    if (pt.columns < m) throw std::logic_error("output_sensitivities: the tangents stopped early");
    const Eigen::Map<const MatrixXd> X1(pt.x, n, m), V1(pt.v, n, m), A1(pt.a, n, m);
    while (next < data_.t.size() && data_.t[next] <= pt.t) {
      const double t = data_.t[next];
      const double h = have_prev ? pt.t - t_prev : 0.0;
      if (h > 0) {
        const auto [h00, h10, h01, h11] = hermite_weights(t, t_prev, h);
        Xs = h00 * X0 + h10 * V0 + h01 * X1 + h11 * V1;
        Vs = h00 * V0 + h10 * A0 + h01 * V1 + h11 * A1;
      } else {
        Xs = X1;
        Vs = V1;
      }
      ux = Xs.col(0);
      uv = Vs.col(0);
      if (accelerations_) output_at(s, solver, t, ux, uv, &a);
      for (int i = 0; i < P; ++i) {
        x = Xs.col(1 + i);
        v = Vs.col(1 + i);
        G.block(static_cast<Eigen::Index>(next) * ns, i, ns, 1) =
            tangent_output_at(solver, accelerations_ ? d[static_cast<std::size_t>(i)] : Derivative{}, t, ux, uv, a, x, v);
      }
      ++next;
    }
    X0 = X1;
    V0 = V1;
    A0 = A1;
    t_prev = pt.t;
    have_prev = true;
  };
  const auto start = run_start(s, d);
  solver.stream_tangent(data_.t.front(), t_end, state_forcing(s), P, Gf, t_end, breakpoints_, visit, &sum,
                        StepAnchor::Start, start.get());
  counters_.solver.Accumulate(sum);
  ++counters_.forward_solves;
  counters_.sensitivity_solves += P;
  counters_.sensitivity_seconds += since(ts);
  return project_initial_state(G, leading);
}

MatrixXd Objective::output_sensitivities_with(const VectorXd& q, const std::vector<RankOneDirection>& extra) {
  if (extra.empty()) return output_sensitivities(q);
  Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  settle_initial_state(s, solver);
  const int n = model_.ndof, ns = data_.sensors();
  std::vector<Derivative> d;
  for (int i = 0; i < size(); ++i) d.push_back(derivative(s, i));
  for (const RankOneDirection& e : extra) {
    if (e.w.size() != n) throw std::logic_error("Objective::output_sensitivities_with: a direction of the wrong size");
    Derivative di;
    di.dM = di.dD = di.dK = SparseMatrix(n, n);
    di.rank_one = e;
    d.push_back(std::move(di));
  }
  const int leading = static_cast<int>(d.size());
  if (solver.has_tangent_solve()) {
    if (estimates_initial_state())
      for (Derivative& di : initial_state_derivatives()) d.push_back(std::move(di));
    return streamed_output_sensitivities(s, solver, d, leading);
  }
  if (estimates_initial_state()) return {};  // its projection needs the streamed tangents
  // Without a tangent stepper: the state, then each tangent on it.
  Trajectory u;
  const double t_end = data_.t.back();
  const std::vector<Trajectory> S = solve_tangents(solver, s, t_end, t_end, u, d);
  MatrixXd G(static_cast<Eigen::Index>(data_.t.size()) * ns, leading);
  VectorXd x(n), v(n), a(n), ux(n), uv(n);
  for (std::size_t k = 0; k < data_.t.size(); ++k) {
    const double t = data_.t[k];
    if (accelerations_) {
      u.eval(t, ux.data(), uv.data());
      output_at(s, solver, t, ux, uv, &a);
    }
    for (int i = 0; i < leading; ++i) {
      S[static_cast<std::size_t>(i)].eval(t, x.data(), v.data());
      G.block(static_cast<Eigen::Index>(k) * ns, i, ns, 1) =
          tangent_output_at(solver, accelerations_ ? d[static_cast<std::size_t>(i)] : Derivative{}, t, ux, uv, a, x, v);
    }
  }
  return G;
}

VectorXd Objective::gauss_newton_product(const VectorXd& q, const VectorXd& v) {
  if (!has_matrix_free_products())
    throw std::logic_error("Objective::gauss_newton_product: velocity and acceleration sensors are not supported");
  if (v.size() != size()) throw std::invalid_argument("Objective::gauss_newton_product: v has the wrong size");
  if (estimates_initial_state())
    throw std::logic_error("Objective::gauss_newton_product: an estimated initial state takes the Gauss-Newton matrix");
  const Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  const int n = model_.ndof, ns = data_.sensors();
  const double t0 = data_.t.front();
  if (const std::size_t L = checkpoint_spacing(solver); L > 0) {
    // Checkpointed (docs/theory.md §7.9): the tangent's outputs and every L-th state point are kept.
    const std::vector<Derivative> dv{derivative_along(s.dcdq * v)};
    const SecondOrderSolver::TangentForcing G = tangent_forcing(dv);
    const auto ts = Clock::now();
    CheckpointRecorder ck(n, L);
    Trajectory out(ns);
    SolverSummary sum;
    solver.stream_tangent(t0, T_, state_forcing(s), 1, G, T_, breakpoints_,
                          [&](const SecondOrderSolver::Point& pt) {
                            ck(pt);
                            if (pt.columns < 2) throw std::logic_error("gauss_newton_product: the tangent stopped early");
                            push_outputs(Cs_, out, pt.t, pt.x + n, pt.v + n, pt.a + n);  // the tangent's column
                          },
                          &sum);
    counters_.solver.Accumulate(sum);
    ++counters_.forward_solves;
    ++counters_.sensitivity_solves;
    counters_.sensitivity_seconds += since(ts);
    VectorXd gc = VectorXd::Zero(model_.ncoef), yd(ns);
    DisplacementSources src(
        *this, [&](double t, VectorXd& y) { out.eval(t, y.data(), yd.data()); }, false);
    backward_checkpointed(s, solver, src, std::move(ck.checkpoints()), L, gc);
    return s.dcdq.transpose() * gc;
  }
  // Tangent along v: M Ṡ̈ + D Ṡ + K S = −(∂_v M ü + ∂_v D u̇ + ∂_v K u − ∂_v B f), ∂_v = Σ v_i ∂_i.
  Trajectory u;
  const std::vector<Trajectory> S = solve_tangents(solver, s, T_, T_, u, {derivative_along(s.dcdq * v)});
  const Trajectory& Sv = S.front();
  // Costate with the tangent's output in place of the residual: M P'' + D P' + K P = −Cᵀ R C S(T − τ),
  // then Eq. 25 on it and the state.
  VectorXd sx(n), sv(n), gc = VectorXd::Zero(model_.ncoef);
  DisplacementSources src(
      *this,
      [&](double t, VectorXd& y) {
        Sv.eval(t, sx.data(), sv.data());
        y.noalias() = C_ * sx;
      },
      false);
  backward_stored(s, solver, u, src, Sv.times(), gc);
  return s.dcdq.transpose() * gc;
}


// ---- The initial state (docs/theory.md §6.9) ----

void Objective::make_initial_state_basis() {
  // The model's lowest modes at the start values, docs/theory.md §6.9:
  // the rigid-body modes (below the floor) and the lowest initial_state_modes flexible ones.
  VectorXd c;
  MatrixXd dcdq;
  params_.coefficients(params_.initial(), c, dcdq);
  const AssembledModel ops = assemble(model_, c);
  LowestModesOptions few;
  few.flexible = options_.initial_state_modes;
  const NaturalModes nm = few_or_all_modes(ops.M, ops.K, few);
  Eigen::Index rigid = 0;
  while (rigid < nm.omega.size() && nm.omega[rigid] < nm.floor) ++rigid;
  basis_ = nm.vectors.leftCols(std::min<Eigen::Index>(rigid + options_.initial_state_modes, nm.vectors.cols()));
  basis_omega_ = nm.omega.head(basis_.cols());
}


std::vector<Objective::Derivative> Objective::initial_state_derivatives() const {
  const MatrixXd& B = basis_;
  const int n = model_.ndof;
  std::vector<Derivative> d;
  const Derivative none = derivative_along(VectorXd::Zero(model_.ncoef));
  for (int kind = 0; kind < 2; ++kind)
    for (Eigen::Index j = 0; j < B.cols(); ++j) {
      Derivative dj = none;
      dj.x0 = kind == 0 ? VectorXd(B.col(j)) : VectorXd(VectorXd::Zero(n));
      dj.v0 = kind == 1 ? VectorXd(B.col(j)) : VectorXd(VectorXd::Zero(n));
      d.push_back(std::move(dj));
    }
  return d;
}

std::unique_ptr<SecondOrderSolver::InitialState> Objective::run_start(const Setup& s, const std::vector<Derivative>& d) const {
  bool any = s.initial != nullptr;
  for (const Derivative& di : d) any = any || di.x0.size() > 0 || di.v0.size() > 0;
  if (!any) return nullptr;
  const int n = model_.ndof;
  auto st = std::make_unique<SecondOrderSolver::InitialState>();
  st->x = MatrixXd::Zero(n, 1 + static_cast<Eigen::Index>(d.size()));
  st->v = MatrixXd::Zero(n, 1 + static_cast<Eigen::Index>(d.size()));
  if (s.initial) {
    st->x.col(0) = s.initial->x.col(0);
    st->v.col(0) = s.initial->v.col(0);
  }
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (d[i].x0.size() > 0) st->x.col(static_cast<Eigen::Index>(i) + 1) = d[i].x0;
    if (d[i].v0.size() > 0) st->v.col(static_cast<Eigen::Index>(i) + 1) = d[i].v0;
  }
  return st;
}

void Objective::settle_initial_state(Setup& s, const SecondOrderSolver& solver) {
  if (!estimates_initial_state()) return;
  if (!solver.has_tangent_solve())
    throw std::logic_error("Objective: an estimated initial state needs the esdirk integrator");
  // J(a) is quadratic: from rest, g_a = ∂J/∂a and H_a = ∂²J/∂a² (the initial-state tangents are
  // the exact derivatives of the discrete state, so this is the discrete cost's minimiser).
  s.initial = nullptr;
  const std::vector<Derivative> d = initial_state_derivatives();
  VectorXd g;
  MatrixXd H;
  gauss_newton_streamed(s, solver, T_, g, H, nullptr, nullptr, &d);
  const VectorXd ab = -pseudo_solve(H, g);
  const MatrixXd& B = basis_;
  const Eigen::Index m = B.cols();
  auto st = std::make_shared<SecondOrderSolver::InitialState>();
  st->x = B * ab.head(m);
  st->v = B * ab.tail(m);
  s.initial = std::move(st);
  s.initial_coefficients = ab;
}

VectorXd Objective::initial_state_coefficients(const VectorXd& q) {
  if (!estimates_initial_state()) return {};
  Setup s = setup(q);
  SecondOrderSolver solver(s.ops.M, s.ops.D, s.ops.K, model_.dof_group, options_.solver);
  settle_initial_state(s, solver);
  return s.initial_coefficients;
}

void Objective::add_initial_velocity_term(const Setup& s, const VectorXd& p0, VectorXd& gc) const {
  // ∫ pᵀ M_j ü dt = [pᵀ M_j u̇]_{t0}^{T} − ∫ ṗᵀ M_j u̇ dt with p(T) = 0: the bracket is −p(t0)ᵀ M_j u̇(t0).
  const VectorXd v0 = s.initial->v.col(0);
  for (const OperatorTerm& t : model_.mass)
    if (t.coefficient >= 0) gc[t.coefficient] -= p0.dot(t.matrix * v0);
}

MatrixXd Objective::project_initial_state(const MatrixXd& G, int leading) const {
  const int P = leading >= 0 ? leading : size();
  if (!estimates_initial_state()) return G;
  const int ns = data_.sensors();
  const Eigen::Index rows = G.rows(), m = G.cols() - P;
  // Each row's weight: 1/σ² of its sensor where stated, else R (rows are sample-major).
  VectorXd w(rows);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const auto k = static_cast<std::size_t>(r % ns);
    const double sd = k < options_.noise_std.size() ? options_.noise_std[k] : 0.0;
    w[r] = sd > 0 && std::isfinite(sd) ? 1.0 / (sd * sd) : R_[k];
  }
  const MatrixXd Ga = G.rightCols(m);
  const MatrixXd WGa = w.asDiagonal() * Ga;
  const MatrixXd X = pseudo_solve(Ga.transpose() * WGa, WGa.transpose() * G.leftCols(P));
  return G.leftCols(P) - Ga * X;
}

}  // namespace scoleid::identify
