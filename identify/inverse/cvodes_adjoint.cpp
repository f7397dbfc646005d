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
  SUNContext ctx = nullptr;
  check(SUNContext_Create(nullptr, &ctx), "SUNContext_Create");
  struct Cleanup {
    std::vector<N_Vector> vecs;
    std::vector<SUNMatrix> mats;
    std::vector<SUNLinearSolver> lss;
    void* cv = nullptr;
    SUNContext ctx = nullptr;
    ~Cleanup() {
      if (cv) CVodeFree(&cv);
      for (auto* l : lss) SUNLinSolFree(l);
      for (auto* a : mats) SUNMatDestroy(a);
      for (auto* v : vecs) N_VDestroy(v);
      SUNContext_Free(&ctx);
    }
  } cl;
  cl.ctx = ctx;
  N_Vector y = N_VNew_Serial(N, ctx), yQ = N_VNew_Serial(1, ctx), yB = N_VNew_Serial(N, ctx), qB = N_VNew_Serial(d.P, ctx);
  cl.vecs = {y, yQ, yB, qB};
  N_VConst(0.0, y);
  N_VConst(0.0, yQ);
  N_VConst(0.0, yB);
  N_VConst(0.0, qB);
  void* cv = CVodeCreate(CV_BDF, ctx);
  cl.cv = cv;
  const double atol = rtol * 1e-6;
  check(CVodeInit(cv, rhs, t0, y), "CVodeInit");
  check(CVodeSStolerances(cv, rtol, atol), "CVodeSStolerances");
  check(CVodeSetUserData(cv, &d), "CVodeSetUserData");
  check(CVodeSetMaxNumSteps(cv, 10000000), "CVodeSetMaxNumSteps");
  SUNMatrix A = SUNDenseMatrix(N, N, ctx);
  SUNLinearSolver LS = SUNLinSol_Dense(y, A, ctx);
  cl.mats.push_back(A);
  cl.lss.push_back(LS);
  check(CVodeSetLinearSolver(cv, LS, A), "CVodeSetLinearSolver");
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

  int which = 0;
  check(CVodeCreateB(cv, CV_BDF, &which), "CVodeCreateB");
  check(CVodeInitB(cv, which, rhsB, T, yB), "CVodeInitB");
  check(CVodeSStolerancesB(cv, which, rtol, atol), "CVodeSStolerancesB");
  check(CVodeSetUserDataB(cv, which, &d), "CVodeSetUserDataB");
  check(CVodeSetMaxNumStepsB(cv, which, 10000000), "CVodeSetMaxNumStepsB");
  SUNMatrix AB = SUNDenseMatrix(N, N, ctx);
  SUNLinearSolver LSB = SUNLinSol_Dense(yB, AB, ctx);
  cl.mats.push_back(AB);
  cl.lss.push_back(LSB);
  check(CVodeSetLinearSolverB(cv, which, LSB, AB), "CVodeSetLinearSolverB");
  check(CVodeQuadInitB(cv, which, rhsQB, qB), "CVodeQuadInitB");
  check(CVodeQuadSStolerancesB(cv, which, rtol, 1e-30), "CVodeQuadSStolerancesB");
  check(CVodeSetQuadErrConB(cv, which, SUNTRUE), "CVodeSetQuadErrConB");
  check(CVodeB(cv, t0, CV_NORMAL), "CVodeB");
  double tB = 0.0;
  check(CVodeGetQuadB(cv, which, &tB, qB), "CVodeGetQuadB");
  res.gradient = -Eigen::Map<const VectorXd>(N_VGetArrayPointer(qB), d.P);  // dG/dq = −qB(t0)
  void* cvB = CVodeGetAdjCVodeBmem(cv, which);
  if (cvB) CVodeGetNumSteps(cvB, &res.backward_steps);
  return res;
}

}  // namespace scoleid::identify
