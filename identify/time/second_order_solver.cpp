#include "scoleid/identify/time/second_order_solver.h"
#include "scoleid/identify/point_failure.h"

#include "scoleid/identify/time/add_members.h"

#include <arkode/arkode_arkstep.h>
#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>

#include <Eigen/SparseCholesky>

#include "scoleid/identify/time/banded_cholesky.h"
#include "scoleid/identify/time/esdirk_stepper.h"
#include "scoleid/identify/time/newton_matrix.h"
#include "scoleid/io/interrupt.h"
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace scoleid::identify {

bool SolverOptions::IsValid(std::string* why) const {
  auto bad = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!(rtol > 0 && rtol < 1)) return bad("rtol must be in (0, 1)");
  if (!(atol_floor > 0)) return bad("atol_floor must be > 0");
  if (max_steps < 1) return bad("max_steps must be >= 1");
  if (!(max_step >= 0)) return bad("max_step must be >= 0");
  if (max_order < 1 || max_order > 5) return bad("max_order must be in [1, 5]");
  if (!(step >= 0)) return bad("step must be >= 0");
  return true;
}

std::string SolverSummary::BriefReport() const {
  std::ostringstream os;
  os << (ok ? "ok" : "FAILED") << ": steps " << steps << ", rhs " << rhs_evaluations << ", factorizations "
     << factorizations << ", error-test failures " << error_test_failures << ", " << wall_seconds << " s";
  if (!ok) os << " (" << message << ")";
  return os.str();
}

void SolverSummary::Accumulate(const SolverSummary& o) {
  using S = SolverSummary;
  add_members(*this, o, &S::steps, &S::rhs_evaluations, &S::factorizations, &S::linear_solves, &S::error_test_failures,
              &S::nonlinear_iterations, &S::wall_seconds);
}

namespace {


// RAII owners for the SUNDIALS objects of one solve.
struct Context {
  SUNContext ctx = nullptr;
  Context() {
    if (SUNContext_Create(nullptr, &ctx) != 0) throw std::runtime_error("SUNContext_Create failed");
  }
  ~Context() { SUNContext_Free(&ctx); }
};
struct Vector {
  N_Vector v = nullptr;
  Vector(sunindextype n, SUNContext ctx) : v(N_VNew_Serial(n, ctx)) {
    if (!v) throw std::runtime_error("N_VNew_Serial failed");
  }
  ~Vector() { N_VDestroy(v); }
  double* data() const { return N_VGetArrayPointer(v); }
};
struct CvodeMem {
  void* mem = nullptr;
  explicit CvodeMem(SUNContext ctx) : mem(CVodeCreate(CV_BDF, ctx)) {
    if (!mem) throw std::runtime_error("CVodeCreate failed");
  }
  ~CvodeMem() { CVodeFree(&mem); }
};
struct ArkodeMem {
  void* mem = nullptr;
  ~ArkodeMem() { ARKStepFree(&mem); }
};

void check(int retval, const char* what) {
  if (retval < 0) throw std::runtime_error(std::string(what) + " failed with flag " + std::to_string(retval));
}

}  // namespace

struct SecondOrderSolver::Impl {
  int n = 0;
  SparseMatrix M, D, K;   // on the common pattern of M, D, K
  std::vector<int> group;
  int ngroups = 1;
  SolverOptions opt;
  BandedCholesky mass_chol;
  std::unique_ptr<NewtonMatrix> newton;   // mutable through the pointer: its cache
  std::unique_ptr<EsdirkStepper> stepper;

  // Per-solve state (solve() is const but single-threaded per object).
  mutable long linear_solves = 0;
  mutable std::vector<double> group_max, group_floor;
  mutable const Forcing* forcing = nullptr;
  mutable Eigen::VectorXd F, tmp;
  mutable void* integrator_mem = nullptr;
  mutable int (*get_gamma)(void*, double*) = nullptr;
  mutable std::string callback_error;
  mutable std::exception_ptr callback_exception;  // rethrown unless a point failure (point_failure.h)

  void rhs(double t, const double* y, double* ydot) const {
    const double* x = y;
    const double* v = y + n;
    std::copy_n(v, n, ydot);
    F.setZero();
    (*forcing)(t, F.data());
    acceleration(F.data(), x, v, ydot + n);
  }
  void acceleration(const double* Fp, const double* x, const double* v, double* a) const {
    Eigen::Map<const Eigen::VectorXd> X(x, n), V(v, n), Fm(Fp, n);
    Eigen::Map<Eigen::VectorXd> A(a, n);
    A = Fm;
    A.noalias() -= D * V;
    A.noalias() -= K * X;
    mass_chol.solve_in_place(a);
  }
  void newton_solve(double gamma, const double* r, double* sol) const {
    const BandedCholesky& chol = newton->factor(gamma);
    ++linear_solves;
    Eigen::Map<const Eigen::VectorXd> r1(r, n), r2(r + n, n);
    Eigen::Map<Eigen::VectorXd> a(sol, n), b(sol + n, n);
    b.noalias() = M * r2;
    b.noalias() -= gamma * (K * r1);
    chol.solve_in_place(sol + n);
    a = r1 + gamma * b;
  }
  // Reference scale of each group: the quasi-static response x_ref = (K + σM)⁻¹ F to the
  // largest forcing seen on a probe grid, σ = (2π/(t1 − t0))² (so free-floating structures get
  // the rigid-body excursion over the horizon); velocities x_ref · 2π/(t1 − t0).
  void reference_scales(double t0, double t1, const Forcing& f, const std::vector<double>& bps) const {
    const double span = t1 - t0, w0 = 2.0 * 3.14159265358979323846 / span;
    std::vector<double> probes;
    const int np = 256;
    for (int k = 0; k <= np; ++k) probes.push_back(t0 + span * k / np);
    for (double b : bps) probes.push_back(b);
    Eigen::VectorXd best = Eigen::VectorXd::Zero(n), Fp(n);
    for (double t : probes) {
      Fp.setZero();
      f(t, Fp.data());
      if (Fp.squaredNorm() > best.squaredNorm()) best = Fp;
    }
    group_floor.assign(static_cast<std::size_t>(2 * ngroups), opt.atol_floor);
    if (best.squaredNorm() == 0.0) return;
    SparseMatrix Ks = K + (w0 * w0) * M;
    Eigen::SimplicialLDLT<SparseMatrix> ldlt(Ks);
    const Eigen::VectorXd xr = ldlt.solve(best);
    for (int i = 0; i < n; ++i) {
      const auto g = static_cast<std::size_t>(group[static_cast<std::size_t>(i)]);
      group_floor[g] = std::max(group_floor[g], std::abs(xr[i]));
      group_floor[g + static_cast<std::size_t>(ngroups)] = std::max(group_floor[g + static_cast<std::size_t>(ngroups)], std::abs(xr[i]) * w0 * opt.velocity_scale);
    }
  }
  void weights(const double* y, double* w) const {
    const double rtol = opt.rtol;
    for (int i = 0; i < 2 * n; ++i) {
      const int g = (i < n ? group[static_cast<std::size_t>(i)] : ngroups + group[static_cast<std::size_t>(i - n)]);
      group_max[static_cast<std::size_t>(g)] = std::max(group_max[static_cast<std::size_t>(g)], std::abs(y[i]));
    }
    for (int i = 0; i < 2 * n; ++i) {
      const int g = (i < n ? group[static_cast<std::size_t>(i)] : ngroups + group[static_cast<std::size_t>(i - n)]);
      const double atol = rtol * std::max(group_max[static_cast<std::size_t>(g)], group_floor[static_cast<std::size_t>(g)]);
      w[i] = 1.0 / (rtol * std::abs(y[i]) + atol);
    }
  }
};

namespace {
SecondOrderSolver::Impl* impl_of(void* user) { return static_cast<SecondOrderSolver::Impl*>(user); }

int cv_rhs(realtype t, N_Vector y, N_Vector ydot, void* user) {
  auto* s = impl_of(user);
  try {
    s->rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
    return 0;
  } catch (const std::exception& e) {
    s->callback_error = e.what();
    s->callback_exception = std::current_exception();
    return -1;
  }
}

int ark_rhs(realtype t, N_Vector y, N_Vector ydot, void* user) { return cv_rhs(t, y, ydot, user); }

int cv_ewt(N_Vector y, N_Vector ewt, void* user) {
  impl_of(user)->weights(N_VGetArrayPointer(y), N_VGetArrayPointer(ewt));
  return 0;
}

// Matrix-embedded linear solver: the integrator hands us b; we read γ from CVODES.
SUNLinearSolver_Type ls_type(SUNLinearSolver) { return SUNLINEARSOLVER_MATRIX_EMBEDDED; }
SUNLinearSolver_ID ls_id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
int ls_setup(SUNLinearSolver, SUNMatrix) { return 0; }
int ls_solve(SUNLinearSolver LS, SUNMatrix, N_Vector x, N_Vector b, realtype) {
  auto* s = impl_of(LS->content);
  try {
    double gamma = 0.0;
    s->get_gamma(s->integrator_mem, &gamma);
    s->newton_solve(gamma, N_VGetArrayPointer(b), N_VGetArrayPointer(x));
    return 0;
  } catch (const std::exception& e) {
    s->callback_error = e.what();
    s->callback_exception = std::current_exception();
    return -1;
  }
}
int ls_free(SUNLinearSolver LS) {
  LS->content = nullptr;
  SUNLinSolFreeEmpty(LS);
  return 0;
}

SparseMatrix on_pattern(const SparseMatrix& A, const SparseMatrix& pattern) {
  // A re-expressed on `pattern` (which contains A's pattern), explicit zeros kept.
  SparseMatrix out = pattern;
  for (int k = 0; k < out.outerSize(); ++k)
    for (SparseMatrix::InnerIterator it(out, k); it; ++it) it.valueRef() = 0.0;
  for (int k = 0; k < A.outerSize(); ++k)
    for (SparseMatrix::InnerIterator it(A, k); it; ++it) out.coeffRef(it.row(), it.col()) += it.value();
  return out;
}
}  // namespace

SecondOrderSolver::SecondOrderSolver(const SparseMatrix& M, const SparseMatrix& D, const SparseMatrix& K,
                                     std::vector<int> dof_group, SolverOptions options)
    : impl_(std::make_unique<Impl>()) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("SolverOptions: " + why);
  Impl& s = *impl_;
  s.n = static_cast<int>(M.rows());
  s.opt = options;
  // Common pattern: |M| + |D| + |K| with structural ones so that no entry cancels.
  SparseMatrix pattern = M.cwiseAbs() + D.cwiseAbs() + K.cwiseAbs();
  for (int k = 0; k < pattern.outerSize(); ++k)
    for (SparseMatrix::InnerIterator it(pattern, k); it; ++it) it.valueRef() = 1.0;
  pattern.makeCompressed();
  s.M = on_pattern(M, pattern);
  s.D = on_pattern(D, pattern);
  s.K = on_pattern(K, pattern);
  s.group = dof_group.empty() ? std::vector<int>(static_cast<std::size_t>(s.n), 0) : std::move(dof_group);
  s.ngroups = 1 + *std::max_element(s.group.begin(), s.group.end());
  const BandedCholesky::Shape shape = BandedCholesky::shape(pattern);
  s.mass_chol.resize(s.n, shape);
  s.mass_chol.assign(M);
  if (!s.mass_chol.factorize()) throw std::runtime_error("mass matrix is not positive definite");
  s.newton = std::make_unique<NewtonMatrix>(s.M, s.D, s.K, shape);
  if (s.opt.integrator == SolverOptions::Integrator::Esdirk)
    s.stepper = std::make_unique<EsdirkStepper>(s.M, s.D, s.K, s.mass_chol, *s.newton, ButcherTable::arkode_dirk(s.opt.dirk_table));
  s.F.resize(s.n);
  s.tmp.resize(s.n);
}

SecondOrderSolver::~SecondOrderSolver() = default;

int SecondOrderSolver::dim() const { return impl_->n; }

bool SecondOrderSolver::has_tangent_solve() const { return static_cast<bool>(impl_->stepper); }

namespace {
void fill_summary(SolverSummary* summary, const StepperCounters& c, long factorizations,
                  std::chrono::steady_clock::time_point wall0) {
  if (!summary) return;
  *summary = {};
  summary->ok = true;
  summary->steps = c.steps;
  summary->rhs_evaluations = c.stage_forcings;
  summary->linear_solves = c.linear_solves;
  summary->factorizations = factorizations;
  summary->wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
}
}  // namespace


SecondOrderSolver::TangentSolution SecondOrderSolver::solve_tangent(double t0, double t1, const Forcing& forcing, int P,
                                                                    const TangentForcing& tangent, double tangent_end,
                                                                    const std::vector<double>& breakpoints,
                                                                    SolverSummary* summary, StepAnchor anchor,
                                                                    const InitialState* initial) const {
  const Impl& s = *impl_;
  if (!s.stepper) throw std::logic_error("solve_tangent: only the esdirk integrator steps tangents with the state");
  const auto wall0 = std::chrono::steady_clock::now();
  const long f0 = s.newton->factorizations();
  const double h = s.opt.step > 0 ? s.opt.step : (t1 - t0) / 2000.0;
  EsdirkStepper::Result r = s.stepper->run(t0, t1, h, breakpoints, forcing, P, &tangent, tangent_end, anchor, initial);
  fill_summary(summary, r.counters, s.newton->factorizations() - f0, wall0);
  return {std::move(r.state), std::move(r.tangents)};
}


void SecondOrderSolver::stream(double t0, double t1, const Forcing& forcing, const std::vector<double>& breakpoints,
                               const Sink& sink, SolverSummary* summary, const Start* start, double until,
                               StepAnchor anchor, const InitialState* initial) const {
  const Impl& s = *impl_;
  if (!s.stepper) {
    if (start) throw std::logic_error("SecondOrderSolver::stream: only the esdirk integrator resumes a run");
    const Trajectory u = solve(t0, t1, forcing, breakpoints, summary, anchor, initial);
    Point pt;
    pt.resumable = false;
    for (std::size_t k = 0; k < u.size(); ++k) {
      pt.t = u.times()[k];
      pt.x = u.x(k).data();
      pt.v = u.v(k).data();
      pt.a = u.a(k).data();
      sink(pt);
      if (pt.t >= until) break;
    }
    return;
  }
  io::check_interrupt();
  const auto wall0 = std::chrono::steady_clock::now();
  const long f0 = s.newton->factorizations();
  const double h = start ? start->h : (s.opt.step > 0 ? s.opt.step : (t1 - t0) / 2000.0);
  const StepperCounters c =
      s.stepper->stream(t0, t1, h, breakpoints, forcing, sink, 0, nullptr, 0.0, start, until, anchor, initial);
  fill_summary(summary, c, s.newton->factorizations() - f0, wall0);
}

void SecondOrderSolver::stream_tangent(double t0, double t1, const Forcing& forcing, int P, const TangentForcing& tangent,
                                       double tangent_end, const std::vector<double>& breakpoints, const Sink& sink,
                                       SolverSummary* summary, StepAnchor anchor, const InitialState* initial) const {
  const Impl& s = *impl_;
  if (!s.stepper) throw std::logic_error("stream_tangent: only the esdirk integrator steps tangents with the state");
  io::check_interrupt();
  const auto wall0 = std::chrono::steady_clock::now();
  const long f0 = s.newton->factorizations();
  const double h = s.opt.step > 0 ? s.opt.step : (t1 - t0) / 2000.0;
  const StepperCounters c = s.stepper->stream(t0, t1, h, breakpoints, forcing, sink, P, &tangent, tangent_end, nullptr,
                                              std::numeric_limits<double>::infinity(), anchor, initial);
  fill_summary(summary, c, s.newton->factorizations() - f0, wall0);
}

void SecondOrderSolver::acceleration(const double* F, const double* x, const double* v, double* a) const {
  impl_->acceleration(F, x, v, a);
}

namespace {
// One SUNDIALS integration of the first-order system y = (x, v) from rest, with the product's
// own Newton solver (Impl::newton_solve) embedded as the linear solver: CVODES BDF under error
// control, or ARKODE ARKStep with the DIRK table at a fixed step.
class SundialsRun {
public:
  SundialsRun(SecondOrderSolver::Impl& s, double t0, double h)
      : s_(s), bdf_(s.opt.integrator == SolverOptions::Integrator::Bdf), h_(h), y_(2 * s.n, ctx_.ctx),
        ls_(SUNLinSolNewEmpty(ctx_.ctx)) {
    N_VConst(0.0, y_.v);
    if (!ls_.ls) throw std::runtime_error("SUNLinSolNewEmpty failed");
    SUNLinearSolver LS = ls_.ls;
    LS->content = &s;
    LS->ops->gettype = ls_type;
    LS->ops->getid = ls_id;
    LS->ops->setup = ls_setup;
    LS->ops->solve = ls_solve;
    LS->ops->free = ls_free;
    if (bdf_) {
      cv_ = std::make_unique<CvodeMem>(ctx_.ctx);
      s.integrator_mem = cv_->mem;
      s.get_gamma = CVodeGetCurrentGamma;
      check(CVodeInit(cv_->mem, cv_rhs, t0, y_.v), "CVodeInit");
      check(CVodeSetUserData(cv_->mem, &s), "CVodeSetUserData");
      check(CVodeWFtolerances(cv_->mem, cv_ewt), "CVodeWFtolerances");
      check(CVodeSetMaxNumSteps(cv_->mem, s.opt.max_steps), "CVodeSetMaxNumSteps");
      check(CVodeSetMaxOrd(cv_->mem, s.opt.max_order), "CVodeSetMaxOrd");
      if (s.opt.max_step > 0) check(CVodeSetMaxStep(cv_->mem, s.opt.max_step), "CVodeSetMaxStep");
      check(CVodeSetLinearSolver(cv_->mem, LS, nullptr), "CVodeSetLinearSolver");
    } else {
      ark_.mem = ARKStepCreate(nullptr, ark_rhs, t0, y_.v, ctx_.ctx);
      if (!ark_.mem) throw std::runtime_error("ARKStepCreate failed");
      s.integrator_mem = ark_.mem;
      s.get_gamma = ARKStepGetCurrentGamma;
      check(ARKStepSetUserData(ark_.mem, &s), "ARKStepSetUserData");
      const auto table = s.opt.dirk_table < 0 ? ARKODE_ESDIRK324L2SA_4_2_3 : static_cast<ARKODE_DIRKTableID>(s.opt.dirk_table);
      check(ARKStepSetTableNum(ark_.mem, table, ARKODE_ERK_NONE), "ARKStepSetTableNum");
      check(ARKStepWFtolerances(ark_.mem, cv_ewt), "ARKStepWFtolerances");
      check(ARKStepSetLinearSolver(ark_.mem, LS, nullptr), "ARKStepSetLinearSolver");
      check(ARKStepSetLinear(ark_.mem, 0), "ARKStepSetLinear");
      check(ARKStepSetDeduceImplicitRhs(ark_.mem, SUNTRUE), "ARKStepSetDeduceImplicitRhs");
      check(ARKStepSetMaxNumSteps(ark_.mem, s.opt.max_steps), "ARKStepSetMaxNumSteps");
      check(ARKStepSetFixedStep(ark_.mem, h), "ARKStepSetFixedStep");
    }
  }

  double* y() const { return y_.data(); }

  void set_stop(double stop) {
    if (bdf_) check(CVodeSetStopTime(cv_->mem, stop), "CVodeSetStopTime");
    else check(ARKStepSetStopTime(ark_.mem, stop), "ARKStepSetStopTime");
  }

  // One internal step towards `stop`; t is where it ended. A failure throws with the callback's error.
  void one_step(double stop, double& t) {
    const int flag = bdf_ ? CVode(cv_->mem, stop, y_.v, &t, CV_ONE_STEP) : ARKStepEvolve(ark_.mem, stop, y_.v, &t, ARK_ONE_STEP);
    if (flag < 0) {
      std::string msg = std::string(bdf_ ? "CVODES" : "ARKODE") + " failed at t = " + std::to_string(t) + " with flag " +
                        std::to_string(flag);
      if (s_.callback_exception && !point_failure(s_.callback_exception)) std::rethrow_exception(s_.callback_exception);
      if (!s_.callback_error.empty()) msg += ": " + s_.callback_error;
      throw std::runtime_error(msg);
    }
  }

  // Restart past a discontinuity at t. CVodeReInit zeroes the CVODES counters (ARKStepReset keeps
  // ARKODE's), so they are collected first.
  void restart(double t) {
    if (bdf_) {
      collect();
      check(CVodeReInit(cv_->mem, t, y_.v), "CVodeReInit");
    } else {
      check(ARKStepReset(ark_.mem, t, y_.v), "ARKStepReset");
      check(ARKStepSetFixedStep(ark_.mem, h_), "ARKStepSetFixedStep");
    }
  }

  void collect() {
    long st = 0, fe = 0, fi = 0, ef = 0, ni = 0;
    if (bdf_) {
      CVodeGetNumSteps(cv_->mem, &st);
      CVodeGetNumRhsEvals(cv_->mem, &fe);
      CVodeGetNumErrTestFails(cv_->mem, &ef);
      CVodeGetNumNonlinSolvIters(cv_->mem, &ni);
    } else {
      ARKStepGetNumSteps(ark_.mem, &st);
      ARKStepGetNumRhsEvals(ark_.mem, &fe, &fi);
      ARKStepGetNumErrTestFails(ark_.mem, &ef);
      ARKStepGetNumNonlinSolvIters(ark_.mem, &ni);
    }
    steps += st;
    rhs += fe + fi;
    etf += ef;
    nni += ni;
  }

  long steps = 0, rhs = 0, etf = 0, nni = 0;

private:
  struct LSOwner {
    explicit LSOwner(SUNLinearSolver l) : ls(l) {}
    LSOwner(const LSOwner&) = delete;
    LSOwner& operator=(const LSOwner&) = delete;
    SUNLinearSolver ls;
    ~LSOwner() {
      if (ls) SUNLinSolFree(ls);
    }
  };
  SecondOrderSolver::Impl& s_;
  const bool bdf_;
  const double h_;
  Context ctx_;
  Vector y_;
  LSOwner ls_;
  std::unique_ptr<CvodeMem> cv_;
  ArkodeMem ark_;
};
}  // namespace

Trajectory SecondOrderSolver::solve(double t0, double t1, const Forcing& forcing, const std::vector<double>& breakpoints,
                                    SolverSummary* summary, StepAnchor anchor, const InitialState* initial) const {
  io::check_interrupt();  // a SIGINT/SIGTERM ends the run between solves (io/interrupt.h)
  const auto wall0 = std::chrono::steady_clock::now();
  Impl& s = *impl_;
  const int n = s.n;
  const double h = s.opt.step > 0 ? s.opt.step : (t1 - t0) / 2000.0;
  if (s.stepper) {
    const long f0 = s.newton->factorizations();
    EsdirkStepper::Result r = s.stepper->run(t0, t1, h, breakpoints, forcing, 0, nullptr, 0.0, anchor, initial);
    fill_summary(summary, r.counters, s.newton->factorizations() - f0, wall0);
    return std::move(r.state);
  }
  if (initial) throw std::logic_error("SecondOrderSolver::solve: only the esdirk integrator starts from a state other than rest");
  s.forcing = &forcing;
  s.linear_solves = 0;
  s.group_max.assign(static_cast<std::size_t>(2 * s.ngroups), 0.0);
  s.reference_scales(t0, t1, forcing, breakpoints);
  s.callback_error.clear();
  s.callback_exception = nullptr;

  const std::vector<double> stops = segment_ends(breakpoints, t0, t1);

  SundialsRun run(s, t0, h);
  const long factorizations0 = s.newton->factorizations();
  Trajectory traj(n);
  std::vector<double> a(static_cast<std::size_t>(n));
  auto record = [&](double t, const double* yy, bool left_limit) {
    s.F.setZero();
    forcing(left_limit ? std::nextafter(t, -std::numeric_limits<double>::infinity()) : t, s.F.data());
    s.acceleration(s.F.data(), yy, yy + n, a.data());
    traj.push(t, yy, yy + n, a.data());
  };
  record(t0, run.y(), false);

  double t = t0;
  for (std::size_t seg = 0; seg < stops.size(); ++seg) {
    const double stop = stops[seg];
    run.set_stop(stop);
    while (t < stop) {
      io::check_interrupt();  // outside the integrator's callbacks, which turn exceptions into flags
      run.one_step(stop, t);
      if (stop - t <= 1e-12 * std::max(1.0, std::abs(stop))) t = stop;
      const bool at_break = (t >= stop) && seg + 1 < stops.size();
      record(t, run.y(), at_break);
    }
    if (seg + 1 < stops.size()) {
      record(t, run.y(), false);  // the right limit, at the same time
      run.restart(t);
    }
  }
  run.collect();
  if (summary) {
    summary->ok = true;
    summary->steps = run.steps;
    summary->rhs_evaluations = run.rhs;
    summary->error_test_failures = run.etf;
    summary->nonlinear_iterations = run.nni;
    summary->factorizations = s.newton->factorizations() - factorizations0;
    summary->linear_solves = s.linear_solves;
    summary->wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  }
  s.forcing = nullptr;
  return traj;
}

}  // namespace scoleid::identify
