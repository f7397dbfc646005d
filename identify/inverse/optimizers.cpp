#include "scoleid/identify/inverse/optimizers.h"
#include "scoleid/identify/point_failure.h"

#include "scoleid/identify/inverse/gauss_newton_step.h"
#include "scoleid/io/interrupt.h"

#include <chrono>
#include <cmath>
#include <deque>
#include <sstream>

namespace scoleid::identify {

bool OptimizerOptions::IsValid(std::string* why) const {
  auto bad = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (method == io::Method::Auto) return bad("method auto must be resolved before the optimiser (run/strategy.h)");
  if (!(smoothness_weight >= 0)) return bad("smoothness_weight must be >= 0");
  if (!(max_krylov_iterations >= 1)) return bad("max_krylov_iterations must be >= 1");
  if (max_iterations < 0) return bad("max_iterations must be >= 0");
  if (!(gradient_tolerance > 0) || !(step_tolerance > 0)) return bad("tolerances must be > 0");
  for (double w : steepest_weights)
    if (!(w > 0)) return bad("steepest_weights must be > 0");
  if (!(trust_radius > 0) || !(max_trust_radius >= trust_radius)) return bad("need 0 < trust_radius <= max_trust_radius");
  if (!(continuation_misfit > 0)) return bad("continuation_misfit must be > 0");
  if (!(short_horizon_floor >= 0)) return bad("short_horizon_floor must be >= 0");
  if (!(cost_stall >= 0)) return bad("cost_stall must be >= 0");
  if (!(continuation_min_fraction > 0 && continuation_min_fraction <= 1)) return bad("continuation_min_fraction must be in (0, 1]");
  return true;
}

const char* to_string(OptimizerSummary::Termination t) {
  using T = OptimizerSummary::Termination;
  switch (t) {
    case T::StepTolerance: return "step_tolerance";
    case T::GradientTolerance: return "gradient_tolerance";
    case T::CostFloor: return "cost_floor";
    case T::CostStalled: return "cost_stalled";
    case T::MaxIterations: return "max_iterations";
    case T::LineSearchFailed: return "line_search_failed";
    case T::DataExplained: return "data_explained";
    case T::Interrupted: return "interrupted";
  }
  return "?";
}

std::string OptimizerSummary::BriefReport() const {
  std::ostringstream os;
  os << to_string(termination) << " after " << iterations_done << " iterations, J = " << cost << ", "
     << wall_seconds << " s";
  if (!message.empty()) os << " (" << message << ")";
  return os.str();
}

namespace {

using Clock = std::chrono::steady_clock;
using T = OptimizerSummary::Termination;

// The smoothness prior ½ β Σ_chains Σ_j (x_{j+1} − x_j)² on x = log q: value, gradient, product.
struct Smoothness {
  double beta = 0.0;
  std::vector<std::vector<int>> chains;
  double value(const VectorXd& x) const {
    double v = 0.0;
    for (const auto& c : chains)
      for (std::size_t j = 0; j + 1 < c.size(); ++j) v += std::pow(x[c[j + 1]] - x[c[j]], 2);
    return 0.5 * beta * v;
  }
  // β LᵀL (P × P), for the explicit Gauss–Newton matrix
  MatrixXd matrix(Eigen::Index P) const {
    MatrixXd A = MatrixXd::Zero(P, P);
    if (beta == 0.0) return A;
    for (const auto& c : chains)
      for (std::size_t j = 0; j + 1 < c.size(); ++j) {
        const int a = c[j], b = c[j + 1];
        A(a, a) += beta;
        A(b, b) += beta;
        A(a, b) -= beta;
        A(b, a) -= beta;
      }
    return A;
  }
  // β LᵀL y
  VectorXd apply(const VectorXd& y) const {
    VectorXd out = VectorXd::Zero(y.size());
    if (beta == 0.0) return out;
    for (const auto& c : chains)
      for (std::size_t j = 0; j + 1 < c.size(); ++j) {
        const double d = y[c[j + 1]] - y[c[j]];
        out[c[j + 1]] += beta * d;
        out[c[j]] -= beta * d;
      }
    return out;
  }
};

struct Run {
  Misfit& obj;
  const OptimizerOptions& opt;
  const std::function<void(const IterationRecord&)>& cb;
  OptimizerSummary sum;
  const Smoothness prior{opt.smoothness_weight, opt.smoothness_chains};

  // A run that cannot go on: the line search (or the cost) failed, with why.
  void failed(const std::string& why) {
    sum.termination = OptimizerSummary::Termination::LineSearchFailed;
    sum.message = why;
  }
  // The run's end at iteration k, log-parameters x, cost J (on the last horizon: the whole record
  // unless stopped early).
  void conclude(int k, const VectorXd& x, double J) {
    sum.iterations_done = k;
    sum.q = x.array().exp();
    sum.cost = J;
  }
  void record(int k, double J, const VectorXd& q, const VectorXd& gx) {
    IterationRecord r{k, J, q, gx.size() ? gx.cwiseAbs().maxCoeff() : NAN, obj.horizon()};  // (NaN: not evaluated)
    sum.iterations.push_back(r);
    if (cb) cb(r);
  }
  // Horizon continuation: the longest T >= t0 + continuation_min_fraction·(t_end − t0) up to
  // which the misfit profile stays within the bound, never shorter than `current`.
  double horizon_from(const Misfit::MisfitProfile& p, double current) const {
    const double t0 = obj.response_start(), t_end = obj.data_end();
    const double t_min = t0 + opt.continuation_min_fraction * (t_end - t0);
    double T = t_min;
    for (std::size_t i = 0; i < p.t.size(); ++i) {
      if (p.t[i] <= t_min) continue;
      if (!(p.misfit[i] <= opt.continuation_misfit)) break;
      T = p.t[i];
    }
    T = std::max(T, current);
    return T >= t_end - 1e-9 * (t_end - t0) ? t_end : T;
  }
  // The relative decrease below which a Gauss–Newton step is indistinguishable from fitting noise
  // (header: 1/N automatically).
  double gauss_newton_stall() const {
    return opt.cost_stall > 0 ? opt.cost_stall : 1.0 / static_cast<double>(std::max(1L, obj.data_points()));
  }
  bool small_gradient(const VectorXd& gx, double J) const {
    return gx.cwiseAbs().maxCoeff() <= opt.gradient_tolerance * std::max(J, 1e-300);
  }
  // Evaluate J and ∂J/∂x at x (with the smoothness prior's value and gradient if `with_prior` and
  // there is one), or return false if the point is outside the model's domain.
  bool eval_grad(const VectorXd& x, double& J, VectorXd& gx, bool with_prior = true) {
    try {
      const VectorXd q = x.array().exp();
      VectorXd gq;
      J = obj.cost_and_gradient(q, gq);
      gx = q.cwiseProduct(gq);
      if (with_prior && prior.beta > 0) {
        J += prior.value(x);
        gx += prior.apply(x);
      }
      return std::isfinite(J);
    } catch (const std::exception& e) {
      if (!point_failure(e)) throw;
      return false;  // no model at an extreme trial point (integrator failure, a parameter out of range): infeasible
    }
  }
};

// One trust-region loop for both Gauss–Newton methods (header): acceptance, radius, horizon
// continuation and termination live here; the step is the strategy's (explicit Levenberg step,
// gauss_newton_step.h, or truncated CG on matrix-free products). The point the loop stands on:
struct Point {
  double J = 0.0;   // cost with the prior's share, on the current horizon
  double Jd = 0.0;  // the data's share (what the matrix-free strategy tracks)
  VectorXd g;       // ∂J/∂x
  MatrixXd H;       // the Gauss–Newton matrix in x (explicit strategy only)
  bool matrix_kept = false;  // H is another point's (OptimizerOptions::start_matrix)
};

class StepStrategy {
public:
  virtual ~StepStrategy() = default;
  // J and g (and what the step needs) at x on the current horizon; false outside the model's
  // domain. `with_profile`: the strategy may keep the misfit profile of this evaluation.
  virtual bool evaluate(const VectorXd& x, Point& p, bool with_profile) = 0;
  // A trial point: at least J (and the profile when asked); `complete` adds the rest once the
  // point is accepted (false: it cannot be evaluated there). By default the trial is evaluated in full.
  virtual bool evaluate_trial(const VectorXd& x, Point& p, bool with_profile) { return evaluate(x, p, with_profile); }
  virtual bool complete(const VectorXd&, Point&) { return true; }
  virtual void start(const Point&) {}
  // The data's matrix that holds at the run's last point p (OptimizerSummary::end_matrix): its own,
  // else `held` (that of the point before, when the run ended on the step from it); empty by default.
  virtual MatrixXd end_matrix(const Point&, const MatrixXd& /*held*/) const { return {}; }
  // The step from (x, p) inside `radius`; `lambda_floor` the Levenberg floor on a short horizon.
  virtual TrustRegionStep step(const VectorXd& x, const Point& p, double radius, double lambda_floor) = 0;
  // After an accepted step whose decrease beat the prediction by `rho`: a longer step along it.
  virtual void extrapolate(const VectorXd&, const TrustRegionStep&, double, bool, Point&, VectorXd&, double&) {}
  // The misfit profile over the whole record at the accepted point x.
  virtual Misfit::MisfitProfile accepted_profile(const VectorXd& x) = 0;
  virtual const char* no_decrease() const = 0;
  virtual double prior_cost(const VectorXd& x, const Point& p) const = 0;
};

// The loop's state between iterations: the iterate, the point it stands on, the radius.
class TrustRegionLoop {
public:
  TrustRegionLoop(Run& r, VectorXd x, StepStrategy& s)
      : r_(r), obj_(r.obj), s_(s), x_(std::move(x)), t0_(obj_.response_start()), t_end_(obj_.data_end()) {}

  void run() {
    if (!begin()) {
      r_.failed("cost cannot be evaluated at the starting point");
      r_.sum.cost = NAN;  // (no cost: not a zero one)
      r_.sum.q = x_.array().exp();
      return;
    }
    try {
      while (iterate() == Next::Go) {
      }
    } catch (const std::exception& e) {
      if (!point_failure(e)) throw;
      r_.failed(e.what());
    }
    r_.conclude(k_, x_, cur_.J);
    r_.sum.prior_cost = s_.prior_cost(x_, cur_);
    if (full() && r_.sum.termination != T::LineSearchFailed) r_.sum.end_matrix = s_.end_matrix(cur_, held_);
    obj_.set_horizon(t_end_);
  }

private:
  enum class Next { Go, Stop };
  bool full() const { return obj_.horizon() >= t_end_; }
  double doubled() const { return std::min(t_end_, obj_.horizon() + (obj_.horizon() - t0_)); }  // horizons from t0

  // The first horizon (the whole record, or with continuation as far as the start's misfit
  // allows) and the starting point; false if it cannot be evaluated.
  bool begin() {
    obj_.set_horizon(t_end_);
    if (r_.opt.continuation) {
      try {
        obj_.set_horizon(r_.horizon_from(obj_.misfit_profile(x_.array().exp()), t0_));
      } catch (const std::exception& e) {
        if (!point_failure(e)) throw;
        return false;
      }
    }
    if (!s_.evaluate(x_, cur_, false)) return false;
    r_.record(0, cur_.J, x_.array().exp(), cur_.g);
    s_.start(cur_);
    radius_ = r_.opt.trust_radius;
    r_.sum.termination = T::MaxIterations;
    return true;
  }

  // On a short horizon a termination test lengthens the horizon instead; true if it did.
  bool extend(double T_new) {
    if (full() || !(T_new > obj_.horizon())) return false;
    obj_.set_horizon(T_new);
    if (!s_.evaluate(x_, cur_, false)) throw std::runtime_error("cost cannot be evaluated on the longer horizon");
    return true;
  }

  // A kept matrix is replaced by the point's own, and the step taken again.
  Next renew_matrix() {
    cur_.H.resize(0, 0);
    cur_.matrix_kept = false;
    if (!s_.complete(x_, cur_)) throw std::runtime_error("the Gauss-Newton matrix cannot be evaluated at the current point");
    return Next::Go;
  }

  Next iterate() {
    if (cur_.J <= r_.opt.cost_floor || r_.small_gradient(cur_.g, cur_.J)) {
      if (extend(doubled())) return Next::Go;
      r_.sum.termination = cur_.J <= r_.opt.cost_floor ? T::CostFloor : T::GradientTolerance;
      return Next::Stop;
    }
    if (k_ >= r_.opt.max_iterations) return Next::Stop;
    const TrustRegionStep st = s_.step(x_, cur_, radius_, full() ? 0.0 : r_.opt.short_horizon_floor * cur_.J);
    // On the whole record the undamped step's predicted decrease is the most the Gauss–Newton
    // model can gain. A gain of J/N (the stall threshold) is a move of about one standard
    // deviation (δᵀFδ ≈ N ΔJ / J with F ≈ H N / 2J), so below a thousandth of it the step left
    // is within 0.03 std of the minimum: end the run without paying for the trial's solve.
    if (full() && !st.on_boundary && st.predicted <= 1e-3 * r_.gauss_newton_stall() * cur_.J) {
      if (cur_.matrix_kept) return renew_matrix();  // (a kept matrix's prediction: the point's own decides)
      r_.sum.termination = T::CostStalled;
      r_.sum.message = "the Gauss-Newton step left predicts a decrease below 1e-3 of the stall threshold: at the minimum";
      return Next::Stop;
    }
    Point trial;
    const bool profile = r_.opt.continuation && !full();
    bool ok = s_.evaluate_trial(x_ + st.delta, trial, profile) && trial.J < cur_.J;
    const double rho = ok && st.predicted > 0 ? (cur_.J - trial.J) / st.predicted : -1.0;
    // A kept matrix that fails — a step it shaped is rejected, or gains less than the stall
    // threshold — is replaced by the point's own before anything is concluded from it: the
    // trial is dropped and the step taken again.
    if (cur_.matrix_kept && (!ok || cur_.J - trial.J <= r_.gauss_newton_stall() * cur_.J)) return renew_matrix();
    radius_ = update_radius(radius_, st, rho, r_.opt.max_trust_radius);
    VectorXd delta = st.delta;
    if (ok && rho > r_.opt.extrapolation_ratio) s_.extrapolate(x_, st, rho, profile, trial, delta, radius_);
    // A point whose cost alone was taken gets its gradient and matrix now, unless the run ends on
    // it (a stalled or vanishing step on the whole record: nothing is taken from there; a run
    // that goes on from it evaluates it then). One whose gradient or matrix cannot be evaluated
    // is rejected like one whose cost cannot.
    const double step = delta.cwiseAbs().maxCoeff();
    const bool stalled = cur_.J - trial.J <= r_.gauss_newton_stall() * cur_.J;
    const bool ends_here = full() && (stalled || step < r_.opt.step_tolerance);  // (the test in accept)
    if (ok && !ends_here && !s_.complete(x_ + delta, trial)) {
      ok = false;
      radius_ = update_radius(radius_, st, -1.0, r_.opt.max_trust_radius);
    }
    if (!ok) return rejected();
    return accept(std::move(trial), delta, step, stalled, ends_here, profile);
  }

  // A rejected trial: a smaller radius next, until it falls below the step tolerance.
  Next rejected() {
    if (!(radius_ < r_.opt.step_tolerance)) return Next::Go;
    if (extend(doubled())) {
      radius_ = r_.opt.trust_radius;
      return Next::Go;
    }
    r_.sum.termination = T::StepTolerance;
    r_.sum.message = s_.no_decrease();
    return Next::Stop;
  }

  Next accept(Point trial, const VectorXd& delta, double step, bool stalled, bool ends_here, bool profile) {
    x_ += delta;
    // A run ending on this step moved less than the stall threshold's worth (about one standard
    // deviation, §7.4) or less than the step tolerance: the matrix it was taken with holds at its
    // end (end_matrix).
    if (ends_here) held_ = std::move(cur_.H);
    cur_ = std::move(trial);
    ++k_;
    // Lengthen the horizon as far as the new iterate's misfit allows; the iterate is recorded
    // with its cost on the horizon the next step is taken on.
    const bool extended = profile && extend(r_.horizon_from(s_.accepted_profile(x_), obj_.horizon()));
    r_.record(k_, cur_.J, x_.array().exp(), cur_.g);
    if (extended) return Next::Go;
    if (step < r_.opt.step_tolerance || stalled) {
      if (extend(doubled())) return Next::Go;
      r_.sum.termination = step < r_.opt.step_tolerance ? T::StepTolerance : T::CostStalled;
      return Next::Stop;
    }
    return Next::Go;
  }

  Run& r_;
  Misfit& obj_;
  StepStrategy& s_;
  VectorXd x_;
  const double t0_, t_end_;
  Point cur_;
  double radius_ = 0.0;
  int k_ = 0;
  MatrixXd held_;  // the point before's matrix, when the run ends on the step from it
};

void trust_region(Run& r, VectorXd x, StepStrategy& s) { TrustRegionLoop(r, std::move(x), s).run(); }

// Explicit Gauss–Newton: J, g and H from forward sensitivities at every trial point (the misfit
// profile comes with the state solve); the Levenberg step of gauss_newton_step.h. With a
// smoothness prior (§7.8) its value, gradient and (constant) matrix are added to the data's: the
// Gauss–Newton model of the whole cost.
//
// With many parameters (more than kMatrixOnAcceptance) the matrix's P tangents cost many state
// solves (at 64 sections about 20), so a trial point on the whole record gets its cost alone (one
// state solve; with a step matrix of its own, §7.2, its cost and gradient: a state and a costate
// solve) and the matrix only once it is accepted: a rejected trial, and the trials of an
// extrapolation, then cost a state solve or two each. (With few parameters the tangents ride along
// with the state solve almost for free, and an accepted point would pay for a second state solve.)
constexpr Eigen::Index kMatrixOnAcceptance = 16;
class ExplicitStep final : public StepStrategy {
public:
  ExplicitStep(Run& r, Eigen::Index P)
      : r_(r), prior_(r.prior), prior_matrix_(prior_.matrix(P)),
        start_matrix_(r.opt.start_matrix.rows() == P && r.opt.start_matrix.cols() == P && r.opt.start_matrix.allFinite()
                          ? r.opt.start_matrix
                          : MatrixXd()),
        lazy_(P > kMatrixOnAcceptance), separate_(lazy_ && r.obj.has_separate_step_matrix()) {}
  bool evaluate_trial(const VectorXd& xx, Point& p, bool with_profile) override {
    if (!lazy_ || with_profile) return evaluate(xx, p, with_profile);
    try {
      const VectorXd q = xx.array().exp();
      p.H.resize(0, 0);  // completed on acceptance
      if (separate_) {
        VectorXd g;
        p.J = r_.obj.cost_and_gradient(q, g) + prior_.value(xx);
        p.g = q.cwiseProduct(g) + prior_.apply(xx);
        return std::isfinite(p.J) && p.g.allFinite();
      }
      p.J = r_.obj.cost(q) + prior_.value(xx);
      p.g.resize(0);  // completed on acceptance
      return std::isfinite(p.J);
    } catch (const std::exception& e) {
      if (!point_failure(e)) throw;
      return false;
    }
  }
  bool complete(const VectorXd& xx, Point& p) override {
    if (p.g.size() != xx.size()) return evaluate(xx, p, false);
    if (p.H.rows() == xx.size()) return true;
    try {
      const VectorXd q = xx.array().exp();
      MatrixXd H;
      r_.obj.step_matrix(q, H);
      p.H = q.asDiagonal() * H * q.asDiagonal() + prior_matrix_;
      return p.H.allFinite();
    } catch (const std::exception& e) {
      if (!point_failure(e)) throw;
      return false;
    }
  }
  bool evaluate(const VectorXd& xx, Point& p, bool with_profile) override {
    try {
      const VectorXd q = xx.array().exp();
      VectorXd g;
      MatrixXd H;
      // (lazy: J and g on the model's step, the matrix perhaps on a coarser one; misfit.h)
      // (a continuing run's first point: the previous run's matrix, OptimizerOptions::start_matrix)
      if (start_matrix_.rows() == xx.size() && separate_ && !with_profile && r_.obj.horizon() >= r_.obj.data_end()) {
        p.J = r_.obj.recalled_cost_and_gradient(q, g) + prior_.value(xx);
        p.g = q.cwiseProduct(g) + prior_.apply(xx);
        p.H = start_matrix_ + prior_matrix_;
        p.matrix_kept = true;
        start_matrix_.resize(0, 0);
        return std::isfinite(p.J) && p.g.allFinite() && p.H.allFinite();
      }
      start_matrix_.resize(0, 0);
      p.matrix_kept = false;
      p.J = (lazy_ && !with_profile ? r_.obj.gradient_and_step_matrix(q, g, H)
                                    : r_.obj.gauss_newton(q, g, H, with_profile ? &prof_ : nullptr)) +
            prior_.value(xx);
      p.g = q.cwiseProduct(g) + prior_.apply(xx);
      p.H = q.asDiagonal() * H * q.asDiagonal() + prior_matrix_;
      return std::isfinite(p.J) && p.g.allFinite() && p.H.allFinite();
    } catch (const std::exception& e) {
      if (!point_failure(e)) throw;
      return false;
    }
  }
  TrustRegionStep step(const VectorXd&, const Point& p, double radius, double lambda_floor) override {
    return trust_region_step(p.H, p.g, radius, lambda_floor);
  }
  // The cost fell by clearly more than the Gauss–Newton model predicted: the minimum along δ lies
  // further out (the model's curvature along δ is too large — a curved valley, a large residual).
  // Try 2δ, 4δ, … with one state solve each while the cost keeps falling.
  void extrapolate(const VectorXd& x, const TrustRegionStep& st, double, bool profile, Point& trial, VectorXd& delta,
                   double& radius) override {
    double best = 1.0, Jb = trial.J;
    for (double a = 2.0; a <= r_.opt.max_extrapolation && a * st.delta.norm() <= r_.opt.max_trust_radius; a *= 2.0) {
      double Ja = 0.0;
      try {
        Ja = r_.obj.cost((x + a * st.delta).array().exp()) + prior_.value(x + a * st.delta);
      } catch (const std::exception& e) {
        if (!point_failure(e)) throw;
        break;
      }
      if (!(Ja < Jb)) break;
      best = a;
      Jb = Ja;
    }
    if (!(best > 1.0)) return;
    Point far;
    far.J = Jb;  // a lazy trial's whole evaluation: its cost, just taken
    if ((lazy_ && !profile ? std::isfinite(Jb) : evaluate(x + best * st.delta, far, profile)) && far.J < trial.J) {
      delta = best * st.delta;
      trial = std::move(far);
      radius = std::max(radius, std::min(delta.norm(), r_.opt.max_trust_radius));
    } else if (profile) {
      evaluate(x + st.delta, trial, profile);  // restore the profile of the accepted point
    }
  }
  Misfit::MisfitProfile accepted_profile(const VectorXd&) override { return prof_; }
  const char* no_decrease() const override {
    return "no decrease along the damped Gauss-Newton direction: at the minimum to integration accuracy";
  }
  double prior_cost(const VectorXd& x, const Point&) const override { return prior_.value(x); }
  MatrixXd end_matrix(const Point& p, const MatrixXd& held) const override {
    const MatrixXd& H = p.H.rows() == prior_matrix_.rows() ? p.H : held;
    if (!lazy_ || H.rows() != prior_matrix_.rows() || !H.allFinite()) return {};
    return H - prior_matrix_;
  }

private:
  Run& r_;
  const Smoothness& prior_;
  const MatrixXd prior_matrix_;
  MatrixXd start_matrix_;  // OptimizerOptions::start_matrix until the first evaluation
  Misfit::MisfitProfile prof_;
  const bool lazy_;
  const bool separate_;  // lazy, and the step matrix an evaluation of its own (misfit.h)
};

// The gradient methods' search direction in x = log q: the paper's fixed-weight update, steepest
// descent, or the L-BFGS two-loop recursion over the stored pairs (s, y); a direction that does
// not descend is replaced by the scaled negative gradient and the pairs are dropped.
VectorXd lbfgs_direction(const VectorXd& x, const VectorXd& gx, std::deque<std::pair<VectorXd, VectorXd>>& mem, bool steepest,
                         const VectorXd* weights, double alpha0) {
  VectorXd d;
  if (weights) {
    // q ← q − w ∘ ∂J/∂q, taken in x = log q to first order: dx_i = −w_i ∂J/∂q_i / q_i.
    const VectorXd q = x.array().exp();
    d = -(weights->array() * (gx.array() / q.array()) / q.array()).matrix();
  } else if (steepest || mem.empty()) {
    d = -gx;
    if (mem.empty() && !steepest) d *= 0.1 / std::max(1e-300, gx.cwiseAbs().maxCoeff());
    if (steepest) d *= alpha0 / std::max(1e-300, gx.cwiseAbs().maxCoeff()) * 0.1;
  } else {
    // two-loop recursion
    VectorXd qv = gx;
    std::vector<double> al(mem.size());
    for (int i = static_cast<int>(mem.size()) - 1; i >= 0; --i) {
      const auto& [s, y] = mem[static_cast<std::size_t>(i)];
      al[static_cast<std::size_t>(i)] = s.dot(qv) / y.dot(s);
      qv -= al[static_cast<std::size_t>(i)] * y;
    }
    const auto& [sl, yl] = mem.back();
    qv *= sl.dot(yl) / yl.dot(yl);
    for (std::size_t i = 0; i < mem.size(); ++i) {
      const auto& [s, y] = mem[i];
      const double b = y.dot(qv) / y.dot(s);
      qv += (al[i] - b) * s;
    }
    d = -qv;
  }
  if (gx.dot(d) >= 0) {
    mem.clear();
    d = -gx * (0.1 / std::max(1e-300, gx.cwiseAbs().maxCoeff()));
  }
  return d;
}

// L-BFGS or steepest descent with a backtracking line search; the loop's state between iterations.
class LineSearchLoop {
public:
  LineSearchLoop(Run& r, VectorXd x, bool steepest)
      : r_(r), obj_(r.obj), x_(std::move(x)), steepest_(steepest), fixed_weights_(steepest && !r.opt.steepest_weights.empty()),
        // Horizon continuation as for Gauss–Newton (header, Run::horizon_from), from the misfit
        // profile of one extra state solve per accepted step while the horizon is short of the
        // record. The paper's update with fixed weights is reproduced as it is: on the whole record.
        continuation_(r.opt.continuation && !fixed_weights_), t0_(obj_.response_start()), t_end_(obj_.data_end()) {}

  void run() {
    if (!begin()) {
      r_.failed("cost cannot be evaluated at the starting point");
      r_.sum.cost = NAN;  // (no cost: not a zero one)
      r_.sum.q = x_.array().exp();
      obj_.set_horizon(t_end_);
      return;
    }
    r_.record(0, J_, x_.array().exp(), gx_);
    if (fixed_weights_) {
      w_ = Eigen::Map<const VectorXd>(r_.opt.steepest_weights.data(), static_cast<Eigen::Index>(r_.opt.steepest_weights.size()));
      if (w_.size() != x_.size()) {
        obj_.set_horizon(t_end_);
        throw std::invalid_argument("steepest_weights: one weight per parameter");
      }
    }
    r_.sum.termination = T::MaxIterations;
    try {
      while (iterate() == Next::Go) {
      }
    } catch (const std::exception& e) {
      if (!point_failure(e)) throw;
      r_.failed(e.what());
    }
    r_.conclude(k_, x_, J_);
    r_.sum.prior_cost = r_.prior.value(x_);
    obj_.set_horizon(t_end_);
  }

private:
  enum class Next { Go, Stop };
  static constexpr int kPairs = 8;  // curvature pairs kept
  bool full() const { return obj_.horizon() >= t_end_; }
  double doubled() const { return std::min(t_end_, obj_.horizon() + (obj_.horizon() - t0_)); }  // horizons from t0
  double choose_horizon(double current) const { return r_.horizon_from(obj_.misfit_profile(x_.array().exp()), current); }

  bool begin() {
    obj_.set_horizon(t_end_);
    if (continuation_) {
      try {
        obj_.set_horizon(choose_horizon(t0_));
      } catch (const std::exception& e) {
        if (!point_failure(e)) throw;
        return false;
      }
    }
    return r_.eval_grad(x_, J_, gx_);
  }

  // A new horizon is a new cost: its gradient, and the curvature pairs of the old one dropped.
  bool extend(double T_new) {
    if (full() || !(T_new > obj_.horizon())) return false;
    obj_.set_horizon(T_new);
    if (!r_.eval_grad(x_, J_, gx_)) throw std::runtime_error("cost cannot be evaluated on the longer horizon");
    mem_.clear();
    return true;
  }

  Next iterate() {
    if (J_ <= r_.opt.cost_floor || r_.small_gradient(gx_, J_)) {
      if (extend(doubled())) return Next::Go;
      r_.sum.termination = J_ <= r_.opt.cost_floor ? T::CostFloor : T::GradientTolerance;
      return Next::Stop;
    }
    if (k_ >= r_.opt.max_iterations) return Next::Stop;
    VectorXd d = lbfgs_direction(x_, gx_, mem_, steepest_, fixed_weights_ ? &w_ : nullptr, alpha0_);
    const double mx = d.cwiseAbs().maxCoeff();
    if (mx > 1.0) d *= 1.0 / mx;
    // Backtracking to the Armijo condition.
    double a = 1.0, Jn = 0.0;
    VectorXd gn;
    bool ok = false;
    for (int ls = 0; ls < 40; ++ls) {
      if (r_.eval_grad(x_ + a * d, Jn, gn) && Jn <= J_ + 1e-4 * a * gx_.dot(d) && Jn <= J_) {
        ok = true;
        break;
      }
      a *= 0.5;
    }
    if (!ok) {
      if (extend(doubled())) return Next::Go;
      r_.failed("no decrease along the search direction");
      return Next::Stop;
    }
    return accept(a, d, Jn, gn);
  }

  Next accept(double a, const VectorXd& d, double Jn, const VectorXd& gn) {
    const VectorXd s = a * d, y = gn - gx_;
    const bool stalled = J_ - Jn <= (r_.opt.cost_stall > 0 ? r_.opt.cost_stall : 1e-5) * J_;
    x_ += s;
    J_ = Jn;
    gx_ = gn;
    if (!steepest_ && y.dot(s) > 1e-300) {
      mem_.emplace_back(s, y);
      if (static_cast<int>(mem_.size()) > kPairs) mem_.pop_front();
    }
    if (steepest_ && !fixed_weights_) alpha0_ = std::min(1e3, a * 2.0 * alpha0_);
    ++k_;
    const bool extended = continuation_ && !full() && extend(choose_horizon(obj_.horizon()));
    r_.record(k_, J_, x_.array().exp(), gx_);
    if (extended) return Next::Go;
    if (s.cwiseAbs().maxCoeff() < r_.opt.step_tolerance || (stalled && !steepest_)) {
      if (extend(doubled())) return Next::Go;
      r_.sum.termination = s.cwiseAbs().maxCoeff() < r_.opt.step_tolerance ? T::StepTolerance : T::CostStalled;
      return Next::Stop;
    }
    return Next::Go;
  }

  Run& r_;
  Misfit& obj_;
  VectorXd x_;
  const bool steepest_, fixed_weights_, continuation_;
  const double t0_, t_end_;
  double J_ = 0.0, alpha0_ = 1.0;
  VectorXd gx_, w_;
  std::deque<std::pair<VectorXd, VectorXd>> mem_;  // (s, y)
  int k_ = 0;
};

void lbfgs(Run& r, VectorXd x, bool steepest) { LineSearchLoop(r, std::move(x), steepest).run(); }

// Inexact Gauss–Newton–Krylov (docs/theory.md §7.7): the trust-region step from truncated
// conjugate gradients on matrix-free products (Steihaug), stopped at ‖H δ + g‖ <= η ‖g‖ with the
// Eisenstat–Walker forcing η = min(½, √(‖g‖/‖g₀‖)), at the region's boundary, or at negative
// curvature. Each CG iteration costs one product (a tangent and a costate solve); the number of
// iterations follows the directions the data inform, not P. Horizon continuation as for the
// gradient methods (one extra state solve per accepted step while the horizon is short).
class KrylovStep final : public StepStrategy {
public:
  explicit KrylovStep(Run& r) : r_(r), prior_(r.prior) {
    if (!r.obj.has_matrix_free_products())
      throw std::invalid_argument(std::string(io::to_string(io::Method::GaussNewtonKrylov)) +
                                  ": velocity and acceleration sensors are not supported (use " +
                                  io::to_string(io::Method::GaussNewton) + ")");
  }
  bool evaluate(const VectorXd& xx, Point& p, bool) override {
    if (!r_.eval_grad(xx, p.Jd, p.g, false)) return false;  // the data's share; the prior's added here
    p.J = p.Jd + prior_.value(xx);
    p.g += prior_.apply(xx);
    return true;
  }
  void start(const Point& p) override { g0_ = p.g.norm(); }
  TrustRegionStep step(const VectorXd& x, const Point& p, double radius, double) override;
  Misfit::MisfitProfile accepted_profile(const VectorXd& x) override { return r_.obj.misfit_profile(x.array().exp()); }
  const char* no_decrease() const override {
    return "no decrease along the truncated Gauss-Newton step: at the minimum to integration accuracy";
  }
  double prior_cost(const VectorXd&, const Point& p) const override { return p.J - p.Jd; }

private:
  Run& r_;
  const Smoothness& prior_;
  double g0_ = 0.0;
};

// Steihaug–Toint CG on H δ = −g inside ‖δ‖ <= radius, H_x y = q ∘ H_q (q ∘ y) + β LᵀL y.
TrustRegionStep KrylovStep::step(const VectorXd& x, const Point& p, double radius, double) {
  const VectorXd q = x.array().exp();
  auto product = [&](const VectorXd& y) {
    return VectorXd(q.cwiseProduct(r_.obj.gauss_newton_product(q, q.cwiseProduct(y))) + prior_.apply(y));
  };
  const VectorXd& gx = p.g;
  const double eta = std::min(0.5, std::sqrt(gx.norm() / std::max(g0_, 1e-300)));
  VectorXd delta = VectorXd::Zero(x.size()), res = gx, d = -gx;
  bool boundary = false;
  // In exact arithmetic CG ends within P iterations; beyond that the products' own error rules.
  const int max_cg = std::min(r_.opt.max_krylov_iterations, static_cast<int>(x.size()));
  for (int cg = 0; cg < max_cg; ++cg) {
    io::check_interrupt();
    const VectorXd Hd = product(d);
    ++r_.sum.krylov_iterations;
    const double curv = d.dot(Hd);
    auto to_boundary = [&]() {
      // τ >= 0 with ‖δ + τ d‖ = radius
      const double a = d.squaredNorm(), b = 2 * delta.dot(d), c = delta.squaredNorm() - radius * radius;
      const double tau = (-b + std::sqrt(std::max(0.0, b * b - 4 * a * c))) / (2 * a);
      delta += tau * d;
      res += tau * Hd;
      boundary = true;
    };
    if (curv <= 0) {
      to_boundary();
      break;
    }
    const double alpha = res.squaredNorm() / curv;
    if ((delta + alpha * d).norm() >= radius) {
      to_boundary();
      break;
    }
    const double rr = res.squaredNorm();
    delta += alpha * d;
    res += alpha * Hd;
    if (res.norm() <= eta * gx.norm()) break;
    d = -res + (res.squaredNorm() / rr) * d;
  }
  TrustRegionStep st;
  // m(0) − m(δ) = −(gᵀδ + ½ δᵀHδ) with Hδ = res − g.
  st.predicted = -0.5 * (gx.dot(delta) + delta.dot(res));
  st.delta = std::move(delta);
  st.on_boundary = boundary;
  return st;
}

void gauss_newton(Run& r, VectorXd x) {
  ExplicitStep s(r, x.size());
  trust_region(r, std::move(x), s);
}

void gauss_newton_krylov(Run& r, VectorXd x) {
  KrylovStep s(r);
  trust_region(r, std::move(x), s);
}

}  // namespace

void evaluate_start(Misfit& objective, const VectorXd& q0, const OptimizerOptions& options) {
  if (options.method != io::Method::GaussNewton || !q0.allFinite() || !(q0.array() > 0).all()) return;
  const VectorXd x = q0.array().log();  // (the run's q, as minimize makes it: it works in log q)
  const VectorXd q = x.array().exp();
  objective.set_horizon(objective.data_end());
  VectorXd g;
  MatrixXd H;
  try {
    if (q.size() > kMatrixOnAcceptance)
      objective.gradient_and_step_matrix(q, g, H);
    else
      objective.gauss_newton(q, g, H);
  } catch (const std::exception& e) {
    if (!point_failure(e)) throw;
    // (the run meets it)
  }
}

OptimizerSummary minimize(Misfit& objective, const VectorXd& q0, const OptimizerOptions& options,
                          const std::function<void(const IterationRecord&)>& on_iteration) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("OptimizerOptions: " + why);
  const auto t0 = Clock::now();
  Run r{objective, options, on_iteration, {}};
  const VectorXd x0 = q0.array().log();
  // Whatever happens inside, the objective is left on the whole record.
  struct HorizonGuard {
    Misfit& o;
    ~HorizonGuard() { o.set_horizon(o.data_end()); }
  } guard{objective};
  switch (options.method) {
    case io::Method::GaussNewton: gauss_newton(r, x0); break;
    case io::Method::GaussNewtonKrylov: gauss_newton_krylov(r, x0); break;
    case io::Method::Lbfgs:
    case io::Method::SteepestDescent: lbfgs(r, x0, options.method == io::Method::SteepestDescent); break;
    case io::Method::Auto: break;  // refused by IsValid
  }
  r.sum.wall_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return r.sum;
}

}  // namespace scoleid::identify
