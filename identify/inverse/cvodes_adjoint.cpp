#include "scoleid/identify/inverse/cvodes_adjoint.h"

#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <stdexcept>

namespace scoleid::identify {

namespace {

void check(int flag, const char* what) {
  if (flag < 0) throw std::runtime_error(std::string(what) + " failed with flag " + std::to_string(flag));
}

// A SUNContext and everything made in it, freed in reverse order whatever happens.
struct Sundials {
  std::vector<N_Vector> vecs;
  std::vector<SUNMatrix> mats;
  std::vector<SUNLinearSolver> lss;
  void* cv = nullptr;
  SUNContext ctx = nullptr;
  Sundials() { check(SUNContext_Create(nullptr, &ctx), "SUNContext_Create"); }
  Sundials(const Sundials&) = delete;
  Sundials& operator=(const Sundials&) = delete;
  ~Sundials() {
    if (cv) CVodeFree(&cv);
    for (auto* l : lss) SUNLinSolFree(l);
    for (auto* a : mats) SUNMatDestroy(a);
    for (auto* v : vecs) N_VDestroy(v);
    SUNContext_Free(&ctx);
  }
};

// The forward problem in cl.cv: BDF (created by the caller) with a dense solver.
void forward_problem(Sundials& cl, CVRhsFn rhs, double t0, N_Vector y, int n, double rtol, double atol,
                     void* user_data) {
  void* cv = cl.cv;
  check(CVodeInit(cv, rhs, t0, y), "CVodeInit");
  check(CVodeSStolerances(cv, rtol, atol), "CVodeSStolerances");
  check(CVodeSetUserData(cv, user_data), "CVodeSetUserData");
  check(CVodeSetMaxNumSteps(cv, 10000000), "CVodeSetMaxNumSteps");
  SUNMatrix A = SUNDenseMatrix(n, n, cl.ctx);
  SUNLinearSolver LS = SUNLinSol_Dense(y, A, cl.ctx);
  cl.mats.push_back(A);
  cl.lss.push_back(LS);
  check(CVodeSetLinearSolver(cv, LS, A), "CVodeSetLinearSolver");
}

// The backward (adjoint) problem of the forward run in cl.cv: BDF with a dense solver, the
// quadrature qB with error control, both at rtol (quadrature atol 1e-30: relative only).
int backward_problem(Sundials& cl, CVRhsFnB rhsB, CVQuadRhsFnB rhsQB, double T, N_Vector yB, N_Vector qB, int n,
                     double rtol, double atol, void* user_data) {
  void* cv = cl.cv;
  int which = 0;
  check(CVodeCreateB(cv, CV_BDF, &which), "CVodeCreateB");
  check(CVodeInitB(cv, which, rhsB, T, yB), "CVodeInitB");
  check(CVodeSStolerancesB(cv, which, rtol, atol), "CVodeSStolerancesB");
  check(CVodeSetUserDataB(cv, which, user_data), "CVodeSetUserDataB");
  check(CVodeSetMaxNumStepsB(cv, which, 10000000), "CVodeSetMaxNumStepsB");
  SUNMatrix AB = SUNDenseMatrix(n, n, cl.ctx);
  SUNLinearSolver LSB = SUNLinSol_Dense(yB, AB, cl.ctx);
  cl.mats.push_back(AB);
  cl.lss.push_back(LSB);
  check(CVodeSetLinearSolverB(cv, which, LSB, AB), "CVodeSetLinearSolverB");
  check(CVodeQuadInitB(cv, which, rhsQB, qB), "CVodeQuadInitB");
  check(CVodeQuadSStolerancesB(cv, which, rtol, 1e-30), "CVodeQuadSStolerancesB");
  check(CVodeSetQuadErrConB(cv, which, SUNTRUE), "CVodeSetQuadErrConB");
  return which;
}

struct Data {
  int n = 0, P = 0, ns = 0;
  MatrixXd M, D, K, Minv, C0, C1, C2;  // output rows on x, v and a = ẍ (C1, C2 empty without rate sensors)
  std::vector<MatrixXd> dM, dD, dK;
  std::vector<VectorXd> loads;
  std::vector<std::vector<VectorXd>> dloads;  // [param][input]
  VectorXd R;
  Objective* obj = nullptr;

  VectorXd force(double t) const {
    VectorXd F = VectorXd::Zero(n);
    for (std::size_t i = 0; i < loads.size(); ++i) F += obj->input(static_cast<int>(i), t) * loads[i];
    return F;
  }
  // a = M⁻¹(B f − D v − K x)
  VectorXd acceleration(double t, const double* y) const {
    Eigen::Map<const VectorXd> x(y, n), v(y + n, n);
    return Minv * (force(t) - D * v - K * x);
  }
  // r = C0 x + C1 v + C2 a − z̃
  VectorXd residual(double t, const double* y) const {
    VectorXd z(ns);
    obj->data().eval(t, z.data());
    VectorXd r = C0 * Eigen::Map<const VectorXd>(y, n) - z;
    if (C1.size() != 0) r += C1 * Eigen::Map<const VectorXd>(y + n, n) + C2 * acceleration(t, y);
    return r;
  }
  // ν = M⁻¹ C2ᵀ R r (zero without acceleration rows): a's share of g_y and g_q.
  VectorXd nu(const VectorXd& r) const {
    if (C2.size() == 0) return VectorXd::Zero(n);
    return Minv * (C2.transpose() * R.cwiseProduct(r));
  }
};

int rhs(realtype t, N_Vector yv, N_Vector ydot, void* ud) {
  const Data& d = *static_cast<Data*>(ud);
  const double* y = N_VGetArrayPointer(yv);
  double* yd = N_VGetArrayPointer(ydot);
  Eigen::Map<const VectorXd> x(y, d.n), v(y + d.n, d.n);
  Eigen::Map<VectorXd>(yd, d.n) = v;
  Eigen::Map<VectorXd>(yd + d.n, d.n) = d.Minv * (d.force(t) - d.D * v - d.K * x);
  return 0;
}

int rhsQ(realtype t, N_Vector yv, N_Vector qdot, void* ud) {
  const Data& d = *static_cast<Data*>(ud);
  const VectorXd r = d.residual(t, N_VGetArrayPointer(yv));
  N_VGetArrayPointer(qdot)[0] = 0.5 * r.dot(d.R.cwiseProduct(r));
  return 0;
}

int rhsB(realtype t, N_Vector yv, N_Vector yB, N_Vector yBdot, void* ud) {
  const Data& d = *static_cast<Data*>(ud);
  const double* y = N_VGetArrayPointer(yv);
  const double* l = N_VGetArrayPointer(yB);
  double* ld = N_VGetArrayPointer(yBdot);
  Eigen::Map<const VectorXd> lx(l, d.n), lv(l + d.n, d.n);
  const VectorXd w = d.Minv * lv;  // M⁻¹ λ_v (M symmetric)
  const VectorXd r = d.residual(t, y), Rr = d.R.cwiseProduct(r), nu = d.nu(r);
  // λ̇ = −f_yᵀ λ − g_yᵀ,  g_yᵀ = [C0ᵀRr − Kν; C1ᵀRr − Dν]
  Eigen::Map<VectorXd> ldx(ld, d.n), ldv(ld + d.n, d.n);
  ldx = d.K * (w + nu) - d.C0.transpose() * Rr;
  ldv = -lx + d.D * (w + nu);
  if (d.C1.size() != 0) ldv -= d.C1.transpose() * Rr;
  return 0;
}

int rhsQB(realtype t, N_Vector yv, N_Vector yB, N_Vector qBdot, void* ud) {
  const Data& d = *static_cast<Data*>(ud);
  const double* y = N_VGetArrayPointer(yv);
  const double* l = N_VGetArrayPointer(yB);
  Eigen::Map<const VectorXd> x(y, d.n), v(y + d.n, d.n), lv(l + d.n, d.n);
  const VectorXd F = d.force(t);
  const VectorXd a = d.Minv * (F - d.D * v - d.K * x);
  // λᵀ ∂f/∂q_i + g_{q_i} = (M⁻¹λ_v + ν)ᵀ h_i
  VectorXd w = d.Minv * lv;
  if (d.C2.size() != 0) w += d.nu(d.residual(t, y));
  double* qd = N_VGetArrayPointer(qBdot);
  for (int i = 0; i < d.P; ++i) {
    VectorXd h = -(d.dD[static_cast<std::size_t>(i)] * v + d.dK[static_cast<std::size_t>(i)] * x + d.dM[static_cast<std::size_t>(i)] * a);
    for (std::size_t k = 0; k < d.loads.size(); ++k) h += d.obj->input(static_cast<int>(k), t) * d.dloads[static_cast<std::size_t>(i)][k];
    qd[i] = w.dot(h);
  }
  return 0;
}

}  // namespace

CvodesAdjointResult cvodes_adjoint_gradient(Objective& obj, const VectorXd& q, double rtol) {
  const StructuralModel& m = obj.model();
  Data d;
  d.obj = &obj;
  d.n = m.ndof;
  d.P = obj.size();
  d.ns = static_cast<int>(m.sensors.size());
  VectorXd c;
  MatrixXd dcdq;
  obj.parameterization().coefficients(q, c, dcdq);
  const AssembledModel ops = assemble(m, c);
  d.M = MatrixXd(ops.M);
  d.D = MatrixXd(ops.D);
  d.K = MatrixXd(ops.K);
  d.Minv = d.M.inverse();
  d.C0 = m.output_matrix(0);
  if (m.has_rate_outputs()) {
    d.C1 = m.output_matrix(1);
    d.C2 = m.output_matrix(2);
  }
  d.loads = ops.loads;
  d.R = Eigen::Map<const VectorXd>(obj.weights().data(), d.ns);
  for (int i = 0; i < d.P; ++i) {
    MatrixXd A = MatrixXd::Zero(d.n, d.n), B = A, Kk = A;
    for (const auto& t : m.mass) if (t.coefficient >= 0) A += dcdq(t.coefficient, i) * MatrixXd(t.matrix);
    for (const auto& t : m.damping) if (t.coefficient >= 0) B += dcdq(t.coefficient, i) * MatrixXd(t.matrix);
    for (const auto& t : m.stiffness) if (t.coefficient >= 0) Kk += dcdq(t.coefficient, i) * MatrixXd(t.matrix);
    d.dM.push_back(A);
    d.dD.push_back(B);
    d.dK.push_back(Kk);
    std::vector<VectorXd> dl;
    for (const auto& in : m.inputs)
      dl.push_back(in.coefficient >= 0 ? VectorXd(dcdq(in.coefficient, i) * in.vector) : VectorXd(VectorXd::Zero(d.n)));
    d.dloads.push_back(dl);
  }

  const double t0 = obj.data().t.front(), T = obj.horizon();
  const int N = 2 * d.n;
  Sundials cl;
  SUNContext ctx = cl.ctx;
  N_Vector y = N_VNew_Serial(N, ctx), yQ = N_VNew_Serial(1, ctx), yB = N_VNew_Serial(N, ctx), qB = N_VNew_Serial(d.P, ctx);
  cl.vecs = {y, yQ, yB, qB};
  N_VConst(0.0, y);
  N_VConst(0.0, yQ);
  N_VConst(0.0, yB);
  N_VConst(0.0, qB);
  void* cv = CVodeCreate(CV_BDF, ctx);
  cl.cv = cv;
  const double atol = rtol * 1e-6;
  forward_problem(cl, rhs, t0, y, N, rtol, atol, &d);
  check(CVodeQuadInit(cv, rhsQ, yQ), "CVodeQuadInit");
  check(CVodeQuadSStolerances(cv, rtol, 1e-30), "CVodeQuadSStolerances");
  check(CVodeSetQuadErrCon(cv, SUNTRUE), "CVodeSetQuadErrCon");
  check(CVodeAdjInit(cv, 500, CV_HERMITE), "CVodeAdjInit");
  // One forward sweep: CVODES error control handles the forcing's breakpoints (the adjoint
  // module replays the forward problem between checkpoints, and a stop time would be replayed too).
  double t = t0;
  int ncheck = 0;
  check(CVodeF(cv, T, y, &t, CV_NORMAL, &ncheck), "CVodeF");
  check(CVodeGetQuad(cv, &t, yQ), "CVodeGetQuad");
  CvodesAdjointResult res;
  res.cost = N_VGetArrayPointer(yQ)[0];
  CVodeGetNumSteps(cv, &res.forward_steps);

  const int which = backward_problem(cl, rhsB, rhsQB, T, yB, qB, N, rtol, atol, &d);
  check(CVodeB(cv, t0, CV_NORMAL), "CVodeB");
  double tB = 0.0;
  check(CVodeGetQuadB(cv, which, &tB, qB), "CVodeGetQuadB");
  res.gradient = -Eigen::Map<const VectorXd>(N_VGetArrayPointer(qB), d.P);  // dG/dq = −qB(t0)
  void* cvB = CVodeGetAdjCVodeBmem(cv, which);
  if (cvB) CVodeGetNumSteps(cvB, &res.backward_steps);
  return res;
}

}  // namespace scoleid::identify

namespace scoleid::identify {

namespace {

struct NonlinearData {
  const ScoleNonlinear::Dynamics* dyn = nullptr;
  const std::vector<io::Signal>* signals = nullptr;
  int n = 0, ncoef = 0;
  VectorXd inputs(double t) const {
    VectorXd f(static_cast<Eigen::Index>(signals->size()));
    for (std::size_t i = 0; i < signals->size(); ++i) f[static_cast<Eigen::Index>(i)] = (*signals)[i](t);
    return f;
  }
};

// The model's evaluations may throw (a mass block that is not positive definite); an exception
// must not cross CVODES's C frames: it becomes the unrecoverable return −1, and the CVODES call
// that fails reports it (check()).
template <class F>
int guarded(F&& f) {
  try {
    f();
    return 0;
  } catch (...) {
    return -1;
  }
}

int nl_rhs(realtype t, N_Vector yv, N_Vector ydot, void* ud) {
  const NonlinearData& d = *static_cast<NonlinearData*>(ud);
  return guarded([&] { d.dyn->derivative(N_VGetArrayPointer(yv), d.inputs(t), N_VGetArrayPointer(ydot)); });
}

// A backward right-hand side: product(y, inputs, f(t, y), λ) written to out.
template <class Product>
int backward(realtype t, N_Vector yv, N_Vector yB, double* out, int size, void* ud, Product&& product) {
  const NonlinearData& d = *static_cast<NonlinearData*>(ud);
  return guarded([&] {
    const double* y = N_VGetArrayPointer(yv);
    const VectorXd in = d.inputs(t);
    VectorXd yd(d.n);
    d.dyn->derivative(y, in, yd.data());
    const VectorXd lam = Eigen::Map<const VectorXd>(N_VGetArrayPointer(yB), d.n);
    Eigen::Map<VectorXd>(out, size) = product(d, y, in, yd, lam);
  });
}

// λ̇ = −f_yᵀ λ
int nl_rhsB(realtype t, N_Vector yv, N_Vector yB, N_Vector yBdot, void* ud) {
  return backward(t, yv, yB, N_VGetArrayPointer(yBdot), static_cast<NonlinearData*>(ud)->n, ud,
                  [](const NonlinearData& d, const double* y, const VectorXd& in, const VectorXd& yd, const VectorXd& lam) {
                    return VectorXd(-d.dyn->derivative_vjp(y, in, yd, lam));
                  });
}

// qB' = λᵀ ∂f/∂c (integrated from T back: qB(t0) = −∫ λᵀ ∂f/∂c dt)
int nl_rhsQB(realtype t, N_Vector yv, N_Vector yB, N_Vector qBdot, void* ud) {
  return backward(t, yv, yB, N_VGetArrayPointer(qBdot), static_cast<NonlinearData*>(ud)->ncoef, ud,
                  [](const NonlinearData& d, const double* y, const VectorXd& in, const VectorXd& yd, const VectorXd& lam) {
                    return d.dyn->coefficient_vjp(y, in, yd, lam);
                  });
}

}  // namespace

CvodesAdjointResult cvodes_nonlinear_gradient(const ScoleNonlinear& model, const VectorXd& c,
                                              const std::vector<io::Signal>& signals, const Measurements& data,
                                              const std::vector<double>& R, double rtol) {
  const auto dyn = model.at(c);
  NonlinearData d;
  d.dyn = &dyn;
  d.signals = &signals;
  d.n = model.state_size();
  d.ncoef = model.coefficients();
  const int n = d.n, ns = model.sensors(), K = static_cast<int>(data.t.size()), nu = model.speeds();
  if (static_cast<int>(R.size()) != ns) throw std::invalid_argument("cvodes_nonlinear_gradient: one weight per sensor");
  std::vector<double> tau(static_cast<std::size_t>(K), 0.0);
  for (int k = 0; k + 1 < K; ++k) {
    const double dt = data.t[static_cast<std::size_t>(k + 1)] - data.t[static_cast<std::size_t>(k)];
    tau[static_cast<std::size_t>(k)] += 0.5 * dt;
    tau[static_cast<std::size_t>(k + 1)] += 0.5 * dt;
  }
  Sundials cl;
  SUNContext ctx = cl.ctx;
  N_Vector y = N_VNew_Serial(n, ctx), yB = N_VNew_Serial(n, ctx), qB = N_VNew_Serial(d.ncoef, ctx);
  cl.vecs = {y, yB, qB};
  N_VConst(0.0, y);
  N_VConst(0.0, qB);
  void* cv = CVodeCreate(CV_BDF, ctx);
  cl.cv = cv;
  const double atol = rtol * 1e-4;
  const double t0 = data.t.front();
  forward_problem(cl, nl_rhs, t0, y, n, rtol, atol, &d);
  check(CVodeAdjInit(cv, 500, CV_HERMITE), "CVodeAdjInit");

  // A sample's cost, ∂g_k/∂y_k and ∂g_k/∂c (through u̇ for accelerometers).
  CvodesAdjointResult res;
  res.gradient = VectorXd::Zero(d.ncoef);
  std::vector<VectorXd> ys(static_cast<std::size_t>(K));
  auto sample = [&](int k, VectorXd* gy) {
    const VectorXd& yk = ys[static_cast<std::size_t>(k)];
    const VectorXd in = d.inputs(data.t[static_cast<std::size_t>(k)]);
    VectorXd yd(n), udot;
    dyn.derivative(yk.data(), in, yd.data(), &udot);
    const VectorXd z = dyn.outputs(yk.data(), udot);
    VectorXd rho(ns);
    for (int j = 0; j < ns; ++j) {
      const double r = z[j] - data.z(k, j);
      rho[j] = tau[static_cast<std::size_t>(k)] * R[static_cast<std::size_t>(j)] * r;
      if (!gy) res.cost += 0.5 * rho[j] * r;
    }
    if (!gy) return;
    VectorXd dy, da;
    dyn.outputs_vjp(yk.data(), udot, rho, dy, da);
    VectorXd lam = VectorXd::Zero(n);
    lam.tail(nu) = da;
    *gy = dy + dyn.derivative_vjp(yk.data(), in, yd, lam);
    res.gradient += dyn.coefficient_vjp(yk.data(), in, yd, lam);
  };
  ys[0] = VectorXd::Zero(n);
  sample(0, nullptr);
  double t = t0;
  int ncheck = 0;
  for (int k = 1; k < K; ++k) {
    check(CVodeF(cv, data.t[static_cast<std::size_t>(k)], y, &t, CV_NORMAL, &ncheck), "CVodeF");
    ys[static_cast<std::size_t>(k)] = Eigen::Map<const VectorXd>(N_VGetArrayPointer(y), n);
    sample(k, nullptr);
  }
  CVodeGetNumSteps(cv, &res.forward_steps);

  VectorXd gy;
  sample(K - 1, &gy);
  Eigen::Map<VectorXd>(N_VGetArrayPointer(yB), n) = gy;
  const double T = data.t.back();
  const int which = backward_problem(cl, nl_rhsB, nl_rhsQB, T, yB, qB, n, rtol, atol, &d);
  for (int k = K - 2; k >= 0; --k) {
    const double tk = data.t[static_cast<std::size_t>(k)];
    check(CVodeB(cv, tk, CV_NORMAL), "CVodeB");
    double tret = 0.0;
    check(CVodeGetB(cv, which, &tret, yB), "CVodeGetB");
    check(CVodeGetQuadB(cv, which, &tret, qB), "CVodeGetQuadB");
    if (k == 0) break;
    sample(k, &gy);  // the jump λ(t_k⁻) = λ(t_k⁺) + ∂g_k/∂y_k, and the sample's ∂g_k/∂c
    Eigen::Map<VectorXd>(N_VGetArrayPointer(yB), n) += gy;
    check(CVodeReInitB(cv, which, tk, yB), "CVodeReInitB");
    check(CVodeQuadReInitB(cv, which, qB), "CVodeQuadReInitB");
  }
  {
    VectorXd unused;
    sample(0, &unused);  // only its u̇ depends on c
  }
  res.gradient -= Eigen::Map<const VectorXd>(N_VGetArrayPointer(qB), d.ncoef);
  void* cvB = CVodeGetAdjCVodeBmem(cv, which);
  if (cvB) CVodeGetNumSteps(cvB, &res.backward_steps);
  return res;
}

}  // namespace scoleid::identify
