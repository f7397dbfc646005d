// The modal misfit (identify/inverse/modal_misfit.h; docs/theory.md §6.6) and the
// measured-modes file (io/modal_data.h):
//   - gradient against central differences, frequencies alone, with shapes, with damping, on
//     SCOLE (paper-scole-2) and on a pinned–pinned beam with EI on sections;
//   - Taylor remainder of second order;
//   - the sparse path of a large model (the few modes needed, Nelson's method) against the dense one;
//   - a repeated eigenvalue (SCOLE made symmetric: the roll/pitch bending pairs coincide):
//     everything finite, the gradient still exact, the cluster's projected shape fits;
//   - recovery of EI and ρA of SCOLE from six frequencies and shapes synthesised on a finer mesh;
//   - matching by MAC, not by index;
//   - the reader's round trip and its errors.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "scoleid/identify/door/scenario_door.h"
#include "scoleid/identify/fe/modal.h"
#include "scoleid/identify/fe/structure.h"
#include "scoleid/identify/inverse/modal_misfit.h"
#include "scoleid/identify/inverse/optimizers.h"
#include "scoleid/io/error.h"
#include "scoleid/io/modal_data.h"
#include "scoleid/io/scenario.h"

using namespace scoleid::identify;
using scoleid::io::InputError;
using scoleid::io::ModalData;

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;

// A scenario's FE model on `elements` elements and its parameters.
struct FeSetup {
  scoleid::io::Scenario sc;
  std::unique_ptr<FEStructure> st;
  std::unique_ptr<Parameterization> params;
  const StructuralModel& model() const { return st->model(); }
};
FeSetup setup(scoleid::io::Scenario sc, int elements) {
  FeSetup s;
  s.sc = std::move(sc);
  s.st = make_structure(s.sc, elements);
  s.params = s.st->parameterize(s.sc);
  return s;
}

// SCOLE (paper-scole-2) estimating `estimate`.
scoleid::io::Scenario scole(std::vector<std::string> estimate) {
  auto sc = scoleid::io::load_scenario("paper-scole-2");
  sc.identification.estimate = std::move(estimate);
  sc.identification.initial.clear();
  return sc;
}

// The pinned–pinned beam of beam-ei8 with EI on 4 sections and Chen–Russell damping, sensors w1…w8.
scoleid::io::Scenario beam() {
  auto sc = scoleid::io::load_scenario("beam-ei8");
  sc.beam.EI = {23000.0, 30000.0, 36000.0, 27000.0};
  sc.beam.zeta = 0.02;
  sc.identification.estimate = {"EI_1", "EI_2", "EI_3", "EI_4", "rho_A", "zeta"};
  sc.identification.initial.clear();
  return sc;
}

const std::vector<std::string> kScoleStations = {"roll_tip", "pitch_tip", "roll_mid", "pitch_mid"};

MatrixXd station_rows(const StructuralModel& model, const std::vector<std::string>& names) {
  MatrixXd C(static_cast<Eigen::Index>(names.size()), model.ndof);
  for (std::size_t k = 0; k < names.size(); ++k)
    for (const auto& s : model.sensors)
      if (s.name == names[k]) C.row(static_cast<Eigen::Index>(k)) = s.row;
  return C;
}

// The flexible modes of a model at coefficients c, as the misfit defines them.
struct Modes {
  std::vector<double> lambda, f, zeta;
  std::vector<VectorXd> shape;  // C_s φ
  MatrixXd phi;                 // flexible mode vectors (columns)
};
Modes flexible_modes(const StructuralModel& model, const VectorXd& c, const MatrixXd& Cs) {
  const SparseMatrix M = model.assemble(model.mass, c), D = model.assemble(model.damping, c),
                     K = model.assemble(model.stiffness, c);
  const NaturalModes nm = natural_modes(M, K);
  Modes m;
  std::vector<int> idx;
  for (int k = 0; k < nm.omega.size(); ++k)
    if (nm.omega[k] > nm.floor) idx.push_back(k);
  m.phi.resize(model.ndof, static_cast<Eigen::Index>(idx.size()));
  for (std::size_t i = 0; i < idx.size(); ++i) {
    const int k = idx[i];
    const double w = nm.omega[k];
    const VectorXd phi = nm.vectors.col(k);
    m.phi.col(static_cast<Eigen::Index>(i)) = phi;
    m.lambda.push_back(w * w);
    m.f.push_back(w / kTwoPi);
    m.zeta.push_back(phi.dot(D * phi) / (2.0 * w));
    m.shape.push_back(Cs * phi);
  }
  return m;
}
Modes flexible_modes(const FeSetup& s, const VectorXd& q, const std::vector<std::string>& stations) {
  VectorXd c;
  MatrixXd dcdq;
  s.params->coefficients(q, c, dcdq);
  return flexible_modes(s.model(), c, station_rows(s.model(), stations));
}

// Measured modes: the model modes `which` (in that order, labelled 1, 2, …), σ_f = f_rel·f,
// σ_ζ = zeta_rel·ζ (none if <= 0), shapes at `stations` with σ = shape_std (none if empty).
ModalData modal_data(const Modes& m, const std::vector<int>& which, const std::vector<std::string>& stations,
                     double f_rel, double shape_std, double zeta_rel) {
  ModalData d;
  d.source = "synthetic.csv";
  d.stations = stations;
  int label = 0;
  for (int k : which) {
    ModalData::Mode md;
    md.label = ++label;
    md.frequency_hz = m.f[static_cast<std::size_t>(k)];
    md.frequency_std_hz = f_rel * md.frequency_hz;
    if (zeta_rel > 0) {
      md.damping_ratio = m.zeta[static_cast<std::size_t>(k)];
      md.damping_std = zeta_rel * md.damping_ratio;
    }
    if (!stations.empty()) {
      const VectorXd& s = m.shape[static_cast<std::size_t>(k)];
      md.shape.assign(s.data(), s.data() + s.size());
      md.shape_std = shape_std;
    }
    d.modes.push_back(md);
  }
  return d;
}
std::vector<int> first(int n) {
  std::vector<int> v;
  for (int i = 0; i < n; ++i) v.push_back(i);
  return v;
}

// ∂J/∂q by central differences with relative step h in log q.
VectorXd fd_gradient(ModalMisfit& mis, const VectorXd& q, double h) {
  VectorXd g(q.size());
  for (int p = 0; p < q.size(); ++p) {
    VectorXd qp = q, qm = q;
    qp[p] *= std::exp(h);
    qm[p] *= std::exp(-h);
    g[p] = (mis.cost(qp) - mis.cost(qm)) / (2.0 * h * q[p]);
  }
  return g;
}
// max_p |q_p (g_p − g_fd,p)| / max_p |q_p g_p|: the error of the gradient in log q relative to its size.
double gradient_error(const VectorXd& g, const VectorXd& gfd, const VectorXd& q) {
  return (q.cwiseProduct(g - gfd)).cwiseAbs().maxCoeff() / q.cwiseProduct(g).cwiseAbs().maxCoeff();
}

// The gradient against central differences in log q with steps h = 1e-4, 1e-5, 1e-6. The
// differences carry truncation ~h² ∂³J/6 and rounding ~ε_J/h, ε_J the relative rounding of J
// through the dense eigensolve (a few 1e-12 here: the residuals are ~30 standard deviations of
// 1e-3 f): at h = 1e-6 they agree with an exact gradient to a few 1e-6, at the best step to
// ~1e-8. The gradient passes if the error at h = 1e-6 is below 1e-5 and the smallest one below
// 2e-7 (an error of the gradient itself would not shrink with the step).
void check_gradient(ModalMisfit& mis, const VectorXd& q, const char* what) {
  VectorXd g;
  const double J = mis.cost_and_gradient(q, g);
  double best = std::numeric_limits<double>::infinity(), at_1e6 = 0.0;
  std::printf("  %-36s N = %3ld  J = %.6e  |q(g - g_fd)|/|q g| at h =", what, mis.data_points(), J);
  for (double h : {1e-4, 1e-5, 1e-6}) {
    const double err = gradient_error(g, fd_gradient(mis, q, h), q);
    std::printf(" %.0e: %.2e", h, err);
    best = std::min(best, err);
    if (h == 1e-6) at_1e6 = err;
  }
  std::printf("\n");
  EXPECT_TRUE(g.allFinite());
  EXPECT_GT(g.norm(), 0.0);
  EXPECT_LT(at_1e6, 1e-5) << what;
  EXPECT_LT(best, 2e-7) << what;
}

// ∂r/∂q against central differences of the residuals (h = 1e-3, 1e-4, 1e-5 in log q), per block of
// rows — frequencies, damping ratios, shape components — as |(∂r/∂q − FD) diag q|_F /
// |∂r/∂q diag q|_F, so that the small blocks are checked on their own and not hidden behind the
// frequencies. The differences' error is truncation ~h² at the largest step and the eigensolve's
// rounding ~1/h at the smallest (a floor near 1e-7 on SCOLE); the smallest of the three must be
// below 1e-6. The shape rows only where the Jacobian is exact (`shape_rows`: single modes, where a
// held fixed only rescales the shape; a cluster's shape rows hold a fixed and are exact only in the
// gradient).
void check_jacobian(ModalMisfit& mis, const VectorXd& q, const char* what, bool shape_rows = true) {
  const ModalData& d = mis.data();
  const int ns = static_cast<int>(d.stations.size()), nd = d.has_damping() ? 1 : 0, rows = 1 + nd + ns;
  VectorXd r;
  MatrixXd Jac;
  mis.residuals(q, r, &Jac);
  const char* names[] = {"frequency", "damping", "shape"};
  double best[3] = {1e300, 1e300, 1e300};
  std::printf("  %-36s Jacobian vs FD:", what);
  for (double h : {1e-3, 1e-4, 1e-5}) {
    MatrixXd fd(Jac.rows(), Jac.cols());
    for (int p = 0; p < q.size(); ++p) {
      VectorXd qp = q, qm = q, rp, rm;
      qp[p] *= std::exp(h);
      qm[p] *= std::exp(-h);
      mis.residuals(qp, rp);
      mis.residuals(qm, rm);
      fd.col(p) = (rp - rm) / (2.0 * h * q[p]);
    }
    std::printf("  h = %.0e:", h);
    for (int b = 0; b < 3; ++b) {
      if ((b == 1 && nd == 0) || (b == 2 && (ns == 0 || !shape_rows))) continue;
      const int first = b == 0 ? 0 : b == 1 ? 1 : 1 + nd, count = b == 2 ? ns : 1;
      double num = 0.0, den = 0.0;
      for (std::size_t i = 0; i < d.modes.size(); ++i) {
        const Eigen::Index row = static_cast<Eigen::Index>(i) * rows + first;
        num += ((Jac.middleRows(row, count) - fd.middleRows(row, count)) * q.asDiagonal()).squaredNorm();
        den += (Jac.middleRows(row, count) * q.asDiagonal()).squaredNorm();
      }
      const double err = std::sqrt(num / den);
      std::printf(" %s %.1e", names[b], err);
      best[b] = std::min(best[b], err);
    }
  }
  std::printf("\n");
  for (int b = 0; b < 3; ++b)
    if (best[b] < 1e300) {
      EXPECT_LT(best[b], 1e-6) << what << ": " << names[b] << " rows";
    }
}

// Where the SCOLE modal data are taken: q_true * (1.03, 0.98, 1.05, 1.5) for EI, rho_A,
// rho_I_psi, zeta.
VectorXd scole_data_point(const VectorXd& qt) {
  VectorXd qd = qt;
  qd[0] *= 1.03;
  qd[1] *= 0.98;
  qd[2] *= 1.05;
  qd[3] *= 1.5;
  return qd;
}

// The frequency, frequency + shape and frequency + shape + damping misfits of the first six modes:
// each gradient, and the last one's Jacobian, against central differences at q.
void check_misfit_levels(const FeSetup& s, const Modes& m, const std::vector<std::string>& stations, const VectorXd& q) {
  {
    ModalMisfit mis(s.model(), *s.params, modal_data(m, first(6), {}, 1e-3, 0, 0));
    check_gradient(mis, q, "frequencies");
  }
  {
    ModalMisfit mis(s.model(), *s.params, modal_data(m, first(6), stations, 1e-3, 1e-2, 0));
    check_gradient(mis, q, "frequencies + shapes");
  }
  ModalMisfit mis(s.model(), *s.params, modal_data(m, first(6), stations, 1e-3, 1e-2, 0.1));
  check_gradient(mis, q, "frequencies + shapes + damping");
  check_jacobian(mis, q, "frequencies + shapes + damping");
}

}  // namespace

TEST(ModalMisfit, GradientMatchesCentralDifferencesOnScole) {
  const FeSetup s = setup(scole({"EI", "rho_A", "rho_I_psi", "zeta"}), 20);
  const VectorXd qt = s.params->truth();
  const VectorXd qd = scole_data_point(qt);
  const Modes m = flexible_modes(s, qd, kScoleStations);
  std::printf("SCOLE (20 elements, n = %d): data at q_true * (1.03, 0.98, 1.05, 1.5), first 6 flexible modes:\n",
              s.model().ndof);
  for (int k = 0; k < 6; ++k)
    std::printf("  mode %d: f = %.6f Hz, zeta = %.3e\n", k + 1, m.f[static_cast<std::size_t>(k)],
                m.zeta[static_cast<std::size_t>(k)]);
  check_misfit_levels(s, m, kScoleStations, qt);
  {
    ModalMisfit mis(s.model(), *s.params, modal_data(m, first(6), kScoleStations, 1e-3, 1e-2, 0.1));
    // One eigensolve per evaluation point: J, g and H at the same q share it.
    mis.reset_counters();
    const VectorXd q1 = qt * 1.01;
    VectorXd g, Hv;
    MatrixXd H;
    mis.cost_and_gradient(q1, g);
    mis.gauss_newton(q1, g, H);
    EXPECT_EQ(mis.counters().evaluations, 1);
    const VectorXd v = VectorXd::LinSpaced(q1.size(), 1.0, 2.0).cwiseProduct(q1);
    Hv = mis.gauss_newton_product(q1, v);
    EXPECT_LT((Hv - H * v).norm(), 1e-12 * (H * v).norm());
    EXPECT_LT((mis.fisher(q1) - H).norm(), 1e-12 * H.norm());
    Misfit::MisfitProfile prof;
    const double J = mis.gauss_newton(q1, g, H, &prof);
    ASSERT_EQ(prof.t.size(), 1u);
    EXPECT_EQ(prof.t[0], 1.0);
    EXPECT_NEAR(prof.misfit[0], 2.0 * J / static_cast<double>(mis.data_points()), 1e-15 * J);
    EXPECT_EQ(mis.data_points(), 6 * (1 + 1 + 4));
    EXPECT_EQ(mis.counters().evaluations, 1);
  }
}

TEST(ModalMisfit, GradientMatchesCentralDifferencesOnABeam) {
  const FeSetup s = setup(beam(), 16);
  const VectorXd qt = s.params->truth();
  VectorXd qd = qt;
  for (int i = 0; i < qd.size(); ++i) qd[i] *= 1.0 + 0.04 * std::sin(1.0 + 2.0 * i);
  const std::vector<std::string> stations = {"w1", "w2", "w3", "w4", "w5", "w6", "w7", "w8"};
  const Modes m = flexible_modes(s, qd, stations);
  std::printf("pinned-pinned beam (16 elements, EI on 4 sections, n = %d), %zu flexible modes, first %.4f Hz\n",
              s.model().ndof, m.f.size(), m.f[0]);
  check_misfit_levels(s, m, stations, qt);
}

// The sparse path (header: the few modes the matching needs from the sparse solver, the shape and
// damping derivatives by Nelson's method) on the sectioned beam at 128 elements, forced on by
// sparse_from = 0: the residuals and the Jacobian those of the dense path (every mode, the modal
// expansion), the Jacobian against central differences; then on 512 elements (the default threshold),
// where the dense path would solve 1022 modes per evaluation, a fit of the six modes (ρA known)
// from 10 % off lands on the data's point.
TEST(ModalMisfit, TheFewModesOfTheSparsePathGiveTheDenseDerivatives) {
  const FeSetup s = setup(beam(), 128);
  const VectorXd qt = s.params->truth();
  VectorXd qd = qt;
  for (int i = 0; i < qd.size(); ++i) qd[i] *= 1.0 + 0.04 * std::sin(1.0 + 2.0 * i);
  const std::vector<std::string> stations = {"w1", "w2", "w3", "w4", "w5", "w6", "w7", "w8"};
  const ModalData data = modal_data(flexible_modes(s, qd, stations), first(6), stations, 1e-3, 1e-2, 0.1);
  ModalMisfit dense(s.model(), *s.params, data);
  ModalMisfitOptions o;
  o.sparse_from = 0;
  ModalMisfit few(s.model(), *s.params, data, o);
  VectorXd rd, rf;
  MatrixXd Jd, Jf;
  dense.residuals(qt, rd, &Jd);
  few.residuals(qt, rf, &Jf);
  EXPECT_EQ(dense.counters().sparse_evaluations, 0);
  EXPECT_EQ(few.counters().sparse_evaluations, few.counters().evaluations);
  ASSERT_GT(few.counters().sparse_evaluations, 0);
  // The model's quantities behind the residuals (r σ): frequencies and damping ratios relative,
  // unit shapes absolute.
  double df = 0, dz = 0, dpsi = 0;
  for (std::size_t i = 0; i < data.modes.size(); ++i) {
    const auto& md = data.modes[i];
    const Eigen::Index row = static_cast<Eigen::Index>(i) * 10;
    df = std::max(df, std::abs(rf[row] - rd[row]) * md.frequency_std_hz / md.frequency_hz);
    dz = std::max(dz, std::abs(rf[row + 1] - rd[row + 1]) * md.damping_std / md.damping_ratio);
    dpsi = std::max(dpsi, (rf.segment(row + 2, 8) - rd.segment(row + 2, 8)).cwiseAbs().maxCoeff() * md.shape_std);
  }
  const double dJ = (Jf - Jd).norm() / Jd.norm();
  std::printf("  n = %d: sparse against dense path: frequencies %.2e, damping ratios %.2e (relative), unit shapes %.2e, "
              "Jacobian %.2e (relative)\n", s.model().ndof, df, dz, dpsi, dJ);
  // The sparse solver has λ to about ε λ_max absolute (fe/lowest_modes.h), the dense shifted one the
  // low modes to near ε relative: on this mesh they differ by 4.9e-9 in the fundamental (measured),
  // the shapes by 1e-11; an error of the method (a wrong mode, a lost normalisation) would show at
  // the data's scale, 1e-3 and above.
  EXPECT_LT(df, 2e-8);
  EXPECT_LT(dz, 2e-8);
  EXPECT_LT(dpsi, 1e-8);
  EXPECT_LT(dJ, 1e-7);
  check_jacobian(few, qt, "sparse path, freq. + shapes + damping");

  // A fit needs ρA known: modes fix the stiffness only relative to the mass.
  auto sc = beam();
  sc.identification.estimate = {"EI_1", "EI_2", "EI_3", "EI_4", "zeta"};
  const FeSetup big = setup(sc, 512);
  const VectorXd qb = big.params->truth();
  VectorXd qbd = qb, qb0 = qb;
  for (int i = 0; i < qb.size(); ++i) {
    qbd[i] *= 1.0 + 0.04 * std::sin(1.0 + 2.0 * i);
    qb0[i] *= 1.0 + 0.1 * std::cos(3.0 * i);
  }
  const ModalData bd = modal_data(flexible_modes(big, qbd, stations), first(6), stations, 1e-3, 1e-2, 0.1);
  ModalMisfit bm(big.model(), *big.params, bd);
  OptimizerOptions oo;
  oo.method = scoleid::io::Method::GaussNewton;
  oo.max_iterations = 30;
  const auto t0 = std::chrono::steady_clock::now();
  const OptimizerSummary r = minimize(bm, qb0, oo);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("  n = %d: %s after %d iterations, %d eigensolves (%d sparse), %.2f s, |q/q_data - 1| = %.2e\n", big.model().ndof,
              r.message.c_str(), r.iterations_done, bm.counters().evaluations, bm.counters().sparse_evaluations, wall,
              (r.q.cwiseQuotient(qbd).array() - 1.0).abs().maxCoeff());
  EXPECT_TRUE(r.converged()) << r.message;
  EXPECT_EQ(bm.counters().sparse_evaluations, bm.counters().evaluations);
  // The data (noise-free) reproduced to a small fraction of their std, the point to the rounding
  // of a fine beam's fundamental (at 1024 elements measured 8.7e-6 in 0.7 s; the dense path's fit
  // there took 206 s and ended 1.7e-5 off).
  const double chi2 = 2.0 * bm.cost(r.q) / static_cast<double>(bm.data_points());
  std::printf("  chi2 per value at the fit %.2e\n", chi2);
  EXPECT_LT(chi2, 1e-4);
  EXPECT_LT((r.q.cwiseQuotient(qbd).array() - 1.0).abs().maxCoeff(), 1e-4);
}

TEST(ModalMisfit, TaylorRemainderFallsAtSecondOrder) {
  const FeSetup s = setup(scole({"EI", "rho_A", "rho_I_psi", "zeta"}), 20);
  const VectorXd qt = s.params->truth();
  const VectorXd qd = scole_data_point(qt);
  ModalMisfit mis(s.model(), *s.params,
                  modal_data(flexible_modes(s, qd, kScoleStations), first(6), kScoleStations, 1e-3, 1e-2, 0.1));
  std::mt19937_64 rng(7);
  std::normal_distribution<double> N01;
  VectorXd d(qt.size());
  for (int i = 0; i < d.size(); ++i) d[i] = N01(rng);
  const VectorXd v = qt.cwiseProduct(d / d.norm());
  VectorXd g;
  const double J0 = mis.cost_and_gradient(qt, g);
  const double slope = g.dot(v);
  std::vector<double> R;
  std::printf("  %10s %14s %8s\n", "eps", "remainder", "order");
  for (double eps : {1e-2, 1e-3, 1e-4}) {
    R.push_back(std::abs(mis.cost(qt + eps * v) - J0 - eps * slope));
    const double order = R.size() > 1 ? std::log10(R[R.size() - 2] / R.back()) : 0.0;
    std::printf("  %10.0e %14.6e %8.4f\n", eps, R.back(), order);
    if (R.size() > 1) {
      EXPECT_GE(order, 1.8);
      EXPECT_LE(order, 2.2);
    }
  }
}

TEST(ModalMisfit, RepeatedEigenvalueGivesFiniteExactDerivatives) {
  // SCOLE made symmetric about the mast axis: no reflector offset, equal shuttle roll and pitch
  // inertia, no products of inertia, equal bending stiffness; the roll and pitch bending modes
  // then come in exactly repeated pairs.
  auto sc = scole({"EI", "rho_A"});
  sc.scole.reflector_rx = 0.0;
  sc.scole.reflector_ry = 0.0;
  sc.scole.shuttle.Iyy = sc.scole.shuttle.Ixx;
  sc.scole.shuttle.Ixy = sc.scole.shuttle.Ixz = sc.scole.shuttle.Iyz = 0.0;
  sc.scole.reflector.Ixy = sc.scole.reflector.Ixz = sc.scole.reflector.Iyz = 0.0;
  sc.scole.reflector.Iyy = sc.scole.reflector.Ixx;
  sc.scole.EI_pitch = sc.scole.EI_roll;
  const FeSetup s = setup(sc, 20);
  const VectorXd qt = s.params->truth();
  const VectorXd qd = qt.cwiseProduct(Eigen::Vector2d(1.02, 0.99));
  const Modes m = flexible_modes(s, qd, kScoleStations);
  // The first two pairs: consecutive modes whose eigenvalues coincide.
  std::vector<int> pair_start;
  for (std::size_t k = 0; k + 1 < m.lambda.size() && pair_start.size() < 2; ++k) {
    const double gap = (m.lambda[k + 1] - m.lambda[k]) / m.lambda[k + 1];
    if (gap < 1e-6) {
      std::printf("  repeated pair: flexible modes %zu, %zu at %.6f Hz, relative eigenvalue gap %.2e\n", k, k + 1,
                  m.f[k], gap);
      EXPECT_LT(gap, 1e-8);
      pair_start.push_back(static_cast<int>(k));
      ++k;
    }
  }
  ASSERT_EQ(pair_start.size(), 2u);
  EXPECT_EQ(pair_start[0], 0) << "the first flexible modes are the first bending pair";
  // Measured shapes: pure roll and pure pitch (the eigensolver's basis of each pair is arbitrary).
  ModalData d;
  d.source = "symmetric.csv";
  d.stations = kScoleStations;
  int label = 0;
  for (int k : pair_start) {
    MatrixXd S(4, 2);
    S << m.shape[static_cast<std::size_t>(k)], m.shape[static_cast<std::size_t>(k) + 1];
    // roll: pitch_tip (row 1) zero; pitch: roll_tip (row 0) zero.
    for (int row : {1, 0}) {
      const Eigen::Vector2d a(S(row, 1), -S(row, 0));
      const VectorXd shape = S * a;
      EXPECT_LT(std::abs(shape[row + 2]), 1e-9 * shape.norm()) << "the pair is spanned by pure roll and pure pitch";
      ModalData::Mode md;
      md.label = ++label;
      md.frequency_hz = 0.5 * (m.f[static_cast<std::size_t>(k)] + m.f[static_cast<std::size_t>(k) + 1]);
      md.frequency_std_hz = 1e-3 * md.frequency_hz;
      md.shape.assign(shape.data(), shape.data() + 4);
      md.shape_std = 1e-2;
      d.modes.push_back(md);
    }
  }
  ModalMisfit mis(s.model(), *s.params, d);
  // At the data's parameters the clusters reproduce the data: MAC 1, J 0.
  const auto at_data = mis.matches(qd);
  for (const auto& mt : at_data) {
    std::printf("  measured %d -> model mode %d (cluster of %d), MAC = 1 - %.2e\n", mt.measured, mt.model,
                mt.cluster_size, 1.0 - mt.mac);
    EXPECT_EQ(mt.cluster_size, 2);
    EXPECT_GT(mt.mac, 1.0 - 1e-10);
  }
  EXPECT_NE(at_data[0].model, at_data[1].model) << "each member of the pair is assigned once";
  EXPECT_LT(mis.cost(qd), 1e-12);
  VectorXd r, g;
  MatrixXd Jac;
  const double J = mis.residuals(qt, r, &Jac);
  mis.cost_and_gradient(qt, g);
  EXPECT_TRUE(std::isfinite(J));
  EXPECT_TRUE(r.allFinite());
  EXPECT_TRUE(Jac.allFinite());
  EXPECT_TRUE(g.allFinite());
  check_gradient(mis, qt, "repeated pair: frequencies + shapes");
  check_jacobian(mis, qt, "repeated pair: frequencies + shapes", false);
  // Forced onto the sparse path (sparse_from 0; two extra candidates, so that the few modes pay on
  // this small model): with shapes a matched cluster takes the dense solution, whose residuals and
  // Jacobian these are exactly; with frequencies alone the cluster's mean eigenvalue needs only its
  // own modes and the sparse solution stands.
  for (const bool shapes : {true, false}) {
    ModalData dd = d;
    if (!shapes) {
      dd.stations.clear();
      for (auto& md : dd.modes) {
        md.shape.clear();
        md.shape_std = NAN;
      }
    }
    ModalMisfitOptions o0, of;
    o0.extra_candidates = of.extra_candidates = 2;
    of.sparse_from = 0;
    ModalMisfit dense0(s.model(), *s.params, dd, o0), few(s.model(), *s.params, dd, of);
    VectorXd r0, rf;
    MatrixXd J0, Jf;
    dense0.residuals(qt, r0, &J0);
    few.residuals(qt, rf, &Jf);
    EXPECT_EQ(few.counters().sparse_evaluations, 1) << shapes;
    EXPECT_EQ(few.counters().evaluations, shapes ? 2 : 1) << "with shapes: the sparse modes, then every mode";
    const double dr = (rf - r0).cwiseAbs().maxCoeff() / r0.cwiseAbs().maxCoeff(), dj = (Jf - J0).norm() / J0.norm();
    std::printf("  sparse path, %s: residuals %.2e, Jacobian %.2e from the dense path's\n", shapes ? "with shapes" : "frequencies", dr, dj);
    if (shapes) {
      EXPECT_EQ(dr, 0.0);
      EXPECT_EQ(dj, 0.0);
    } else {
      EXPECT_LT(dr, 1e-9);
      EXPECT_LT(dj, 1e-9);
    }
  }
  // The same with the frequencies' weight negligible, so that the gradient is that of the
  // projected shapes (exact by the envelope argument, modal_misfit.h).
  ModalData shape_only = d;
  for (auto& md : shape_only.modes) md.frequency_std_hz = 1e3 * md.frequency_hz;
  ModalMisfit mis_s(s.model(), *s.params, shape_only);
  check_gradient(mis_s, qt, "repeated pair: shapes (frequency weight 1e-12)");
}

TEST(ModalMisfit, RecoversScoleBendingStiffnessAndMassFromModesOfAFinerMesh) {
  const auto start = std::chrono::steady_clock::now();
  constexpr int kElements = 20;
  constexpr int kDataElements = 4 * kElements;
  const auto sc = scole({"EI", "rho_A"});
  const FeSetup s = setup(sc, kElements);
  const FeSetup fine = setup(sc, kDataElements);
  const VectorXd qt = s.params->truth();
  const Modes mf = flexible_modes(fine, fine.params->truth(), kScoleStations);
  const Modes mc = flexible_modes(s, qt, kScoleStations);
  // Discretisation error of the identifier's mesh in the data it fits.
  double df = 0.0, ds = 0.0;
  for (std::size_t k = 0; k < 6; ++k) {
    df = std::max(df, std::abs(mc.f[k] / mf.f[k] - 1.0));
    const VectorXd a = mc.shape[k].normalized(), b = mf.shape[k].normalized();
    ds = std::max(ds, std::min((a - b).norm(), (a + b).norm()));
  }
  std::printf("  %d vs %d elements at the truth: max relative frequency difference %.2e, max shape difference %.2e\n",
              kElements, kDataElements, df, ds);
  EXPECT_LT(df, 1e-5) << "discretisation error well below the 1e-4 asked of the estimates";
  ModalData d = modal_data(mf, first(6), kScoleStations, 1e-4, 1e-3, 0);
  ModalMisfit mis(s.model(), *s.params, d);
  const VectorXd q0 = qt.cwiseProduct(Eigen::Vector2d(1.1, 0.9));
  OptimizerOptions opt;
  opt.method = scoleid::io::Method::GaussNewton;
  const OptimizerSummary sum = minimize(mis, q0, opt);
  const VectorXd err = (sum.q.array() / qt.array() - 1.0).abs();
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "  gauss-newton: %s after %d iterations, J = %.3e, |EI/EI_true - 1| = %.2e, |rho_A/rho_A_true - 1| = %.2e "
      "(%d eigensolves, %.2f s)\n",
      to_string(sum.termination), sum.iterations_done, sum.cost, err[0], err[1], mis.counters().evaluations, secs);
  EXPECT_TRUE(sum.converged());
  EXPECT_LT(err[0], 1e-4);
  EXPECT_LT(err[1], 1e-4);
  for (const auto& mt : mis.matches(sum.q)) EXPECT_EQ(mt.model, mt.measured);
}

TEST(ModalMisfit, MatchesByShapeNotByIndex) {
  const FeSetup s = setup(scole({"EI", "rho_A", "rho_I_psi", "zeta"}), 20);
  const VectorXd qt = s.params->truth();
  VectorXd qd = qt;
  qd[0] *= 1.02;
  qd[1] *= 0.99;
  const Modes m = flexible_modes(s, qd, kScoleStations);
  // Rows out of the model's order, flexible mode 2 missing.
  const std::vector<int> order = {1, 0, 4, 3, 5};
  for (bool shapes : {true, false}) {
    ModalData d = modal_data(m, order, shapes ? kScoleStations : std::vector<std::string>{}, 1e-3, 1e-2, 0);
    ModalMisfit mis(s.model(), *s.params, d);
    for (int at = 0; at < 2; ++at) {
      const VectorXd& q = at == 0 ? qd : qt;
      const auto mt = mis.matches(q);
      ASSERT_EQ(mt.size(), order.size());
      for (std::size_t i = 0; i < order.size(); ++i) {
        std::printf("  %s, %s: row %zu (model mode %d) -> model mode %d, MAC %.6f, f %.5f Hz vs %.5f Hz\n",
                    shapes ? "by MAC" : "by frequency", at == 0 ? "at the data's q" : "at q_true", i, order[i],
                    mt[i].model, mt[i].mac, mt[i].frequency_hz, d.modes[i].frequency_hz);
        EXPECT_EQ(mt[i].measured, static_cast<int>(i));
        EXPECT_EQ(mt[i].model, order[i]);
        if (shapes) {
          EXPECT_GT(mt[i].mac, 0.99);
        } else {
          EXPECT_TRUE(std::isnan(mt[i].mac));
        }
      }
    }
    EXPECT_LT(mis.cost(qd), 1e-12);
  }
}

TEST(ModalData, RoundTripAndErrors) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("modal_data_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  ModalData d;
  d.source = "memory";
  d.stations = {"roll_tip", "pitch_tip"};
  for (int k = 0; k < 3; ++k) {
    ModalData::Mode m;
    m.label = 2 * k + 1;
    m.frequency_hz = 0.1 + std::sqrt(2.0) * k;
    m.frequency_std_hz = 1e-4 * m.frequency_hz / 3.0;
    m.damping_ratio = 0.001 * (k + 1) / 7.0;
    m.damping_std = 1e-4 / 3.0;
    m.shape = {std::sin(1.0 + k), -std::cos(2.0 + k) / 3.0};
    m.shape_std = 1e-3 / 7.0;
    d.modes.push_back(m);
  }
  const std::string path = (dir / "modes.csv").string();
  scoleid::io::write_modal_data(path, d);
  const ModalData r = scoleid::io::read_modal_data(path);
  EXPECT_EQ(r.source, path);
  EXPECT_EQ(r.stations, d.stations);
  ASSERT_EQ(r.modes.size(), d.modes.size());
  EXPECT_TRUE(r.has_damping());
  EXPECT_TRUE(r.has_shapes());
  for (std::size_t k = 0; k < d.modes.size(); ++k) {
    EXPECT_EQ(r.modes[k].label, d.modes[k].label);
    EXPECT_EQ(r.modes[k].frequency_hz, d.modes[k].frequency_hz);
    EXPECT_EQ(r.modes[k].frequency_std_hz, d.modes[k].frequency_std_hz);
    EXPECT_EQ(r.modes[k].damping_ratio, d.modes[k].damping_ratio);
    EXPECT_EQ(r.modes[k].damping_std, d.modes[k].damping_std);
    EXPECT_EQ(r.modes[k].shape, d.modes[k].shape);
    EXPECT_EQ(r.modes[k].shape_std, d.modes[k].shape_std);
  }
  // Frequencies only, columns in another order, comments and blank lines.
  const ModalData f = scoleid::io::read_modal_data_text(
      "# measured\nfrequency_std_hz,mode,frequency_hz\n\n1e-3,1,0.25\n# between\n2e-3,4,0.5\n", "f.csv");
  ASSERT_EQ(f.modes.size(), 2u);
  EXPECT_FALSE(f.has_damping());
  EXPECT_FALSE(f.has_shapes());
  EXPECT_EQ(f.modes[1].label, 4);
  EXPECT_EQ(f.modes[1].frequency_hz, 0.5);
  EXPECT_EQ(f.modes[1].frequency_std_hz, 2e-3);
  EXPECT_TRUE(std::isnan(f.modes[0].damping_ratio));
  // No temporary file left behind.
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 1);

  // Each bad input: InputError naming the file and the offending column or value.
  struct Bad {
    const char* what;
    std::string text;
    std::vector<std::string> expect;
  };
  const std::string H = "mode,frequency_hz,frequency_std_hz";
  const std::vector<Bad> bad = {
      {"empty", "", {"bad.csv", "empty"}},
      {"comments only", "# nothing\n\n", {"bad.csv", "empty"}},
      {"missing column", "mode,frequency_hz\n1,0.3\n", {"bad.csv", "line 1", "frequency_std_hz"}},
      {"duplicate column", H + ",shape_std,roll_tip,roll_tip\n", {"bad.csv", "duplicate column 'roll_tip'"}},
      {"empty column name", H + ",,x\n", {"bad.csv", "column 4 has an empty name"}},
      {"no modes", H + "\n", {"bad.csv", "no modes"}},
      {"too few station values",
       H + ",shape_std,roll_tip,pitch_tip\n1,0.3,1e-4,1e-3,1.0\n",
       {"bad.csv", "line 2", "expected 6 fields", "got 5"}},
      {"non-numeric", H + "\n1,abc,1e-4\n", {"bad.csv", "line 2", "column 'frequency_hz'", "abc"}},
      {"NaN", H + "\n1,nan,1e-4\n", {"bad.csv", "column 'frequency_hz'", "finite", "nan"}},
      {"inf", H + "\n1,0.3,inf\n", {"bad.csv", "column 'frequency_std_hz'", "finite", "inf"}},
      {"negative frequency", H + "\n1,-0.3,1e-4\n", {"bad.csv", "line 2", "column 'frequency_hz'", "> 0", "-0.3"}},
      {"zero frequency", H + "\n1,0,1e-4\n", {"bad.csv", "column 'frequency_hz'", "> 0"}},
      {"zero std", H + "\n1,0.3,0\n", {"bad.csv", "column 'frequency_std_hz'", "> 0", "got 0"}},
      {"negative damping",
       H + ",damping_ratio,damping_std\n1,0.3,1e-4,-0.01,1e-3\n",
       {"bad.csv", "column 'damping_ratio'", ">= 0", "-0.01"}},
      {"zero damping std",
       H + ",damping_ratio,damping_std\n1,0.3,1e-4,0.01,0\n",
       {"bad.csv", "column 'damping_std'", "> 0"}},
      {"damping without its std", H + ",damping_ratio\n1,0.3,1e-4,0.01\n", {"bad.csv", "damping_std", "damping_ratio"}},
      {"damping std alone", H + ",damping_std\n1,0.3,1e-4,0.01\n", {"bad.csv", "damping_ratio"}},
      {"stations without shape_std", H + ",roll_tip\n1,0.3,1e-4,1\n", {"bad.csv", "roll_tip", "shape_std"}},
      {"shape_std without stations", H + ",shape_std\n1,0.3,1e-4,1e-3\n", {"bad.csv", "shape_std"}},
      {"zero shape std", H + ",shape_std,roll_tip\n1,0.3,1e-4,0,1\n", {"bad.csv", "column 'shape_std'", "> 0"}},
      {"labels not increasing",
       H + "\n2,0.3,1e-4\n1,0.5,1e-4\n",
       {"bad.csv", "line 3", "column 'mode'", "increasing", "1 after 2"}},
      {"label not an integer", H + "\n1.5,0.3,1e-4\n", {"bad.csv", "column 'mode'", "1.5"}},
      {"label not positive", H + "\n0,0.3,1e-4\n", {"bad.csv", "column 'mode'", "'0'"}},
  };
  for (const auto& b : bad) {
    try {
      scoleid::io::read_modal_data_text(b.text, "bad.csv");
      ADD_FAILURE() << b.what << ": no error";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      std::printf("  %-28s %s\n", b.what, msg.c_str());
      EXPECT_EQ(msg.find('\n'), std::string::npos) << b.what;
      for (const auto& s : b.expect)
        EXPECT_NE(msg.find(s), std::string::npos) << b.what << ": '" << s << "' not in: " << msg;
    }
  }
  try {
    scoleid::io::read_modal_data((dir / "missing.csv").string());
    ADD_FAILURE() << "missing file: no error";
  } catch (const InputError& e) {
    std::printf("  %-28s %s\n", "missing file", e.what());
    EXPECT_NE(std::string(e.what()).find("missing.csv"), std::string::npos);
  }

  // The door's checks (identify::check_modal_data): stations must be sensors of the scenario on the
  // displacement; a measured shape must not vanish (io::validate_modal_data). The misfit built
  // around the door on the same data is a defect (std::logic_error), not an input error.
  const FeSetup s = setup(scole({"EI", "rho_A"}), 10);
  const auto refuse = [&](const FeSetup& f, const ModalData& data, const std::vector<std::string>& expect, const char* what) {
    try {
      scoleid::identify::check_modal_data(data, f.sc);
      ADD_FAILURE() << what << ": no error";
    } catch (const InputError& e) {
      std::printf("  %-28s %s\n", what, e.what());
      for (const auto& x : expect) EXPECT_NE(std::string(e.what()).find(x), std::string::npos) << what << ": " << x;
    }
    EXPECT_THROW(ModalMisfit(f.model(), *f.params, data), std::logic_error) << what;
  };
  const ModalData ok =
      scoleid::io::read_modal_data_text(H + ",shape_std,roll_tip,pitch_tip\n1,0.3,1e-4,1e-3,1,0.5\n", "m.csv");
  EXPECT_NO_THROW(scoleid::identify::check_modal_data(ok, s.sc));
  EXPECT_NO_THROW(ModalMisfit(s.model(), *s.params, ok));
  ModalData unknown = ok;
  unknown.stations[1] = "pitch_top";
  refuse(s, unknown, {"m.csv", "pitch_top", "is not a sensor of the scenario read on the displacement", "no such sensor"},
         "unknown station");
  // A sensor of the scenario, but on ü.
  const FeSetup slew = setup(scoleid::io::load_scenario("scole-slew"), 10);
  ModalData acc = ok;
  acc.stations[1] = "acc_tip_y";
  refuse(slew, acc, {"m.csv", "acc_tip_y", "is not a sensor of the scenario read on the displacement", "acceleration"},
         "acceleration station");
  ModalData zero = ok;
  zero.modes[0].shape = {0.0, 0.0};
  refuse(s, zero, {"m.csv", "mode 1", "vanish"}, "zero shape");
  fs::remove_all(dir);
}

TEST(ModalMisfit, DampingDataNeedADampedModel) {
  // A two-mass chain with no damping terms.
  StructuralModel model;
  model.ndof = 2;
  model.ncoef = 1;
  model.coefficient_names = {"k"};
  SparseMatrix I(2, 2), Ks(2, 2);
  I.setIdentity();
  Ks.insert(0, 0) = 2.0;
  Ks.insert(0, 1) = -1.0;
  Ks.insert(1, 0) = -1.0;
  Ks.insert(1, 1) = 1.0;
  model.mass.push_back({I, -1});
  model.stiffness.push_back({Ks, 0});
  ModelSensor x2;
  x2.name = "x2";
  x2.kind = scoleid::io::SensorKind::Displacement;
  x2.row = Eigen::RowVector2d(0.0, 1.0);
  model.sensors.push_back(x2);
  struct Stiffness final : Parameterization {
    std::vector<std::string> n = {"k"};
    const std::vector<std::string>& names() const override { return n; }
    void coefficients(const VectorXd& q, VectorXd& c, MatrixXd& dcdq) const override {
      c = q;
      dcdq = MatrixXd::Identity(1, 1);
    }
    std::map<std::string, double> physical(const VectorXd& q) const override { return {{"k", q[0]}}; }
    VectorXd initial() const override { return VectorXd::Ones(1); }
    VectorXd truth() const override { return VectorXd::Ones(1); }
  } params;
  ModalData d = scoleid::io::read_modal_data_text(
      "mode,frequency_hz,frequency_std_hz,damping_ratio,damping_std\n1,0.1,1e-3,0.01,1e-3\n", "chain.csv");
  // Every structure a scenario describes has damping terms; a model built by hand without them,
  // given damping data, is a caller's defect.
  try {
    ModalMisfit mis(model, params, d);
    ADD_FAILURE() << "no error";
  } catch (const std::logic_error& e) {
    std::printf("  %s\n", e.what());
    EXPECT_NE(std::string(e.what()).find("damping"), std::string::npos);
  }
  // Without the damping columns it is a valid one-parameter problem whose gradient is exact.
  d = scoleid::io::read_modal_data_text("mode,frequency_hz,frequency_std_hz,shape_std,x2\n1,0.1,1e-3,1e-2,1\n",
                                        "chain.csv");
  ModalMisfit mis(model, params, d);
  const VectorXd q = VectorXd::Constant(1, 1.3);
  VectorXd g;
  mis.cost_and_gradient(q, g);
  const double gfd = fd_gradient(mis, q, 1e-6)[0];
  std::printf("  chain: g = %.10e, g_fd = %.10e\n", g[0], gfd);
  EXPECT_NEAR(g[0], gfd, 1e-7 * std::abs(gfd));
}
