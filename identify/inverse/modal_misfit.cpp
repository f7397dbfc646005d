#include "scoleid/identify/inverse/modal_misfit.h"

#include <Eigen/SVD>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "scoleid/identify/fe/modal.h"
#include "scoleid/io/error.h"

namespace scoleid::identify {

namespace {

// The assignment of least total cost of rows to distinct columns (rows <= columns): the
// Hungarian method with potentials, O(rows² · columns). Returns the column of each row.
std::vector<int> least_cost_assignment(const MatrixXd& a) {
  const int n = static_cast<int>(a.rows()), m = static_cast<int>(a.cols());
  if (n == 0) return {};
  if (n > m) throw std::domain_error("ModalMisfit: more measured modes than model candidates");
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(static_cast<std::size_t>(n) + 1, 0.0), v(static_cast<std::size_t>(m) + 1, 0.0);
  std::vector<int> p(static_cast<std::size_t>(m) + 1, 0), way(static_cast<std::size_t>(m) + 1, 0);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(static_cast<std::size_t>(m) + 1, inf);
    std::vector<bool> used(static_cast<std::size_t>(m) + 1, false);
    do {
      used[static_cast<std::size_t>(j0)] = true;
      const int i0 = p[static_cast<std::size_t>(j0)];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[static_cast<std::size_t>(j)]) continue;
        const double cur = a(i0 - 1, j - 1) - u[static_cast<std::size_t>(i0)] - v[static_cast<std::size_t>(j)];
        if (cur < minv[static_cast<std::size_t>(j)]) {
          minv[static_cast<std::size_t>(j)] = cur;
          way[static_cast<std::size_t>(j)] = j0;
        }
        if (minv[static_cast<std::size_t>(j)] < delta) {
          delta = minv[static_cast<std::size_t>(j)];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (used[static_cast<std::size_t>(j)]) {
          u[static_cast<std::size_t>(p[static_cast<std::size_t>(j)])] += delta;
          v[static_cast<std::size_t>(j)] -= delta;
        } else {
          minv[static_cast<std::size_t>(j)] -= delta;
        }
      }
      j0 = j1;
    } while (p[static_cast<std::size_t>(j0)] != 0);
    do {
      const int j1 = way[static_cast<std::size_t>(j0)];
      p[static_cast<std::size_t>(j0)] = p[static_cast<std::size_t>(j1)];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> col(static_cast<std::size_t>(n), -1);
  for (int j = 1; j <= m; ++j)
    if (p[static_cast<std::size_t>(j)] > 0) col[static_cast<std::size_t>(p[static_cast<std::size_t>(j)] - 1)] = j - 1;
  return col;
}

}  // namespace

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;
// Singular values of a candidate's station shapes below this fraction of the largest station
// amplitude of the candidates count as zero (a mode the stations do not see).
constexpr double kShapeRankTolerance = 1e-8;

// Σ_terms w_j A_j over the terms that carry a coefficient (constant terms have no derivative).
SparseMatrix along(const std::vector<OperatorTerm>& terms, const VectorXd& dc, int ndof) {
  SparseMatrix A(ndof, ndof);
  for (const auto& t : terms)
    if (t.coefficient >= 0 && dc[t.coefficient] != 0.0) A += dc[t.coefficient] * t.matrix;
  A.makeCompressed();
  return A;
}

}  // namespace

ModalMisfit::ModalMisfit(const StructuralModel& model, const Parameterization& params, io::ModalData data,
                         ModalMisfitOptions options)
    : model_(model), params_(params), data_(std::move(data)), options_(options) {
  if (data_.source.empty()) data_.source = "modal data";
  // Data and options as the door leaves them (io::validate_modal_data; identify::check_modal_data:
  // every station a sensor on u): anything else is a caller's defect.
  auto unchecked = [](const std::string& what) {
    throw std::logic_error("ModalMisfit: " + what + " (the door, identify::check_modal_data, refuses it)");
  };
  if (!(options_.extra_candidates >= 0)) unchecked("extra_candidates < 0");
  if (!(options_.cluster_tolerance >= 0) || !std::isfinite(options_.cluster_tolerance)) unchecked("cluster_tolerance not >= 0");
  if (!(options_.sparse_from >= 0)) unchecked("sparse_from < 0");
  // Stations: sensors acting on u.
  Cs_ = MatrixXd::Zero(static_cast<Eigen::Index>(data_.stations.size()), model_.ndof);
  for (std::size_t k = 0; k < data_.stations.size(); ++k) {
    const std::string& name = data_.stations[k];
    const ModelSensor* found = nullptr;
    for (const auto& s : model_.sensors)
      if (s.name == name) found = &s;
    if (!found || found->order != 0) unchecked("station '" + name + "' is no sensor on u");
    Cs_.row(static_cast<Eigen::Index>(k)) = found->row;
  }
  if (data_.has_damping() && model_.damping.empty()) unchecked("damping data for a model without damping terms");
  for (const auto& m : data_.modes) {
    if (!data_.has_shapes()) break;
    Eigen::Map<const VectorXd> s(m.shape.data(), static_cast<Eigen::Index>(m.shape.size()));
    const double norm = s.stableNorm();
    if (!(norm > 0) || !std::isfinite(norm)) unchecked("mode " + std::to_string(m.label) + "'s shape vanishes");
    measured_shape_.push_back(s / norm);
  }
  rows_per_mode_ = 1 + (data_.has_damping() ? 1 : 0) + static_cast<int>(data_.stations.size());
}

namespace {

// The model's modes as the matching sees them: the flexible modes, grouped in clusters of
// (chained) relative eigenvalue difference below the tolerance, each with its mean eigenvalue,
// frequency, damping ratio and station shapes.
struct Cluster {
  std::vector<int> modes;  // mode indices (columns of Φ)
  double lambda = 0, omega = 0, f = 0, zeta = 0;
  MatrixXd Y;  // C_s Φ_c (stations × m)
  Eigen::JacobiSVD<MatrixXd> svd;
  int rank = 0;
};

struct Spectrum {
  const MatrixXd& Phi;  // the modes computed (all n, or the few of the sparse path), M-orthonormal
  VectorXd lambda;      // ω²
  std::vector<int> flex;        // mode index of flexible mode f
  std::vector<int> cluster_of;  // cluster of flexible mode f
  std::vector<Cluster> cl;      // the clusters the candidates touch
  MatrixXd Y;                   // C_s Φ, all modes (for the shape derivatives)
  int ncand = 0;                // candidates: the first ncand flexible modes
  const Cluster& of(int f) const { return cl[static_cast<std::size_t>(cluster_of[static_cast<std::size_t>(f)])]; }
};

Spectrum cluster_spectrum(const NaturalModes& nm, const SparseMatrix& D, const MatrixXd& Cs, int nmeas, bool shapes,
                          const ModalMisfitOptions& options) {
  Spectrum s{nm.vectors, nm.omega.array().square(), {}, {}, {}, {}, 0};
  const MatrixXd& Phi = s.Phi;
  for (int k = 0; k < nm.omega.size(); ++k)  // every mode, or the few the sparse solver gave
    if (nm.omega[k] > nm.floor) s.flex.push_back(k);
  const int nflex = static_cast<int>(s.flex.size());
  if (nflex < nmeas)
    throw std::domain_error("ModalMisfit: the model has " + std::to_string(nflex) + " flexible modes, the data " +
                            std::to_string(nmeas));
  s.cluster_of.resize(static_cast<std::size_t>(nflex));
  std::vector<std::vector<int>> clusters;  // flexible indices of each cluster
  for (int f = 0; f < nflex; ++f) {
    const double lk = s.lambda[s.flex[static_cast<std::size_t>(f)]];
    if (f > 0 && lk - s.lambda[s.flex[static_cast<std::size_t>(f) - 1]] < options.cluster_tolerance * lk) {
      clusters.back().push_back(f);
    } else {
      clusters.push_back({f});
    }
    s.cluster_of[static_cast<std::size_t>(f)] = static_cast<int>(clusters.size()) - 1;
  }
  s.ncand = std::min(nflex, nmeas + options.extra_candidates);
  const int ncl = s.cluster_of[static_cast<std::size_t>(s.ncand) - 1] + 1;  // clusters touched by the candidates

  s.cl.resize(static_cast<std::size_t>(ncl));
  if (shapes) s.Y = Cs * Phi;
  double shape_scale = 0.0;
  if (shapes)
    for (int f = 0; f < s.ncand; ++f)
      shape_scale = std::max(shape_scale, s.Y.col(s.flex[static_cast<std::size_t>(f)]).norm());
  const Eigen::Index ns = Cs.rows();
  for (int j = 0; j < ncl; ++j) {
    Cluster& C = s.cl[static_cast<std::size_t>(j)];
    for (int f : clusters[static_cast<std::size_t>(j)]) C.modes.push_back(s.flex[static_cast<std::size_t>(f)]);
    const int m = static_cast<int>(C.modes.size());
    double tr_d = 0.0;
    for (int k : C.modes) {
      C.lambda += s.lambda[k] / m;
      tr_d += Phi.col(k).dot(D * Phi.col(k));
    }
    C.omega = std::sqrt(C.lambda);
    C.f = C.omega / kTwoPi;
    C.zeta = tr_d / (2.0 * m * C.omega);
    if (shapes) {
      C.Y.resize(ns, m);
      for (int i = 0; i < m; ++i) C.Y.col(i) = s.Y.col(C.modes[static_cast<std::size_t>(i)]);
      C.svd.compute(C.Y, Eigen::ComputeThinU | Eigen::ComputeThinV);
      const VectorXd& sv = C.svd.singularValues();
      for (int i = 0; i < sv.size(); ++i)
        if (sv[i] > kShapeRankTolerance * shape_scale) ++C.rank;
    }
  }
  return s;
}

// Projection of a measured (unit) shape onto a cluster's station span: the coefficients a and
// the MAC |P ψ_m|².
double project(const Cluster& C, const VectorXd& psi, VectorXd* a) {
  const MatrixXd U = C.svd.matrixU().leftCols(C.rank);
  const VectorXd ut = U.transpose() * psi;
  if (a) *a = C.svd.matrixV().leftCols(C.rank) * (C.svd.singularValues().head(C.rank).cwiseInverse().asDiagonal() * ut);
  return ut.squaredNorm();
}

// One-to-one matching of least total cost (the assignment problem, solved exactly): cost
// 1 − MAC with shapes (relative frequency difference × 1e-6 breaks ties), the relative frequency
// difference without. Candidates a measured shape cannot be matched with (a cluster with no
// station amplitude) are not allowed. Returns the partner candidate and the MAC of each measured mode.
std::vector<int> pair_modes(const Spectrum& s, const io::ModalData& data, const std::vector<VectorXd>& measured_shape,
                            std::vector<double>& mac_of) {
  const bool shapes = data.has_shapes();
  const int nmeas = static_cast<int>(data.modes.size());
  constexpr double kForbidden = 1e30;
  MatrixXd cost = MatrixXd::Constant(nmeas, s.ncand, kForbidden);
  MatrixXd macs = MatrixXd::Constant(nmeas, s.ncand, std::numeric_limits<double>::quiet_NaN());
  for (int i = 0; i < nmeas; ++i) {
    const double fm = data.modes[static_cast<std::size_t>(i)].frequency_hz;
    for (int f = 0; f < s.ncand; ++f) {
      const Cluster& C = s.of(f);
      const double df = std::abs(C.f - fm) / fm;
      if (!shapes) {
        cost(i, f) = df;
        continue;
      }
      if (C.rank == 0) continue;
      macs(i, f) = project(C, measured_shape[static_cast<std::size_t>(i)], nullptr);
      cost(i, f) = (1.0 - macs(i, f)) + 1e-6 * df;
    }
  }
  const std::vector<int> assigned = least_cost_assignment(cost);
  std::vector<int> partner(static_cast<std::size_t>(nmeas), -1);
  mac_of.assign(static_cast<std::size_t>(nmeas), std::numeric_limits<double>::quiet_NaN());
  for (int i = 0; i < nmeas; ++i) {
    const int f = assigned[static_cast<std::size_t>(i)];
    if (f < 0 || !(cost(i, f) < kForbidden)) continue;
    partner[static_cast<std::size_t>(i)] = f;
    mac_of[static_cast<std::size_t>(i)] = macs(i, f);
  }
  for (int i = 0; i < nmeas; ++i)
    if (partner[static_cast<std::size_t>(i)] < 0)
      throw std::domain_error("ModalMisfit: measured mode " + std::to_string(data.modes[static_cast<std::size_t>(i)].label) +
                              " matches no model mode");
  return partner;
}

// A matched model shape at the stations: p = Y_c a, its norm, its unit vector and the sign that
// aligns it with the measured shape.
struct ShapeMatch {
  VectorXd coef, unit;
  double pnorm = 0.0, sign = 1.0;
};

// The derivatives of one cluster's mean eigenvalue, frequency, damping ratio and station shapes
// along one parameter direction (M', K', D'): first-order perturbation theory within the
// M-orthonormal basis Φ, the cluster's own span taken as the normalisation −½ Φ_cᵀ M' Φ_c.
struct ClusterDerivative {
  double dlambda = 0, domega = 0, df = 0, dzeta = 0;
  MatrixXd dY;  // C_s dΦ_c
};

ClusterDerivative cluster_derivative(const Spectrum& s, const Cluster& C, const MatrixXd& W, const SparseMatrix& dM,
                                     const SparseMatrix& dK, const SparseMatrix& dD, bool damping, bool shapes) {
  const MatrixXd& Phi = s.Phi;
  const int n = static_cast<int>(Phi.rows());
  const int m = static_cast<int>(C.modes.size());
  ClusterDerivative d;
  // Coefficients of dΦ_c in the basis Φ: E (n × m).
  MatrixXd Mc(n, m);  // M' Φ_c
  MatrixXd E = MatrixXd::Zero(n, m);
  d.dlambda = 0.0;
  double tr_dD = 0.0;
  for (int i = 0; i < m; ++i) {
    const int k = C.modes[static_cast<std::size_t>(i)];
    const VectorXd phi = Phi.col(k);
    Mc.col(i) = dM * phi;
    const VectorXd v = dK * phi - s.lambda[k] * Mc.col(i);
    d.dlambda += phi.dot(v) / m;
    if (damping) tr_dD += phi.dot(dD * phi);
    const VectorXd G = Phi.transpose() * v;
    for (int j = 0; j < n; ++j) {
      if (std::find(C.modes.begin(), C.modes.end(), j) != C.modes.end()) continue;
      E(j, i) = G[j] / (s.lambda[k] - s.lambda[j]);
    }
  }
  // −½ Φ_c (Φ_cᵀ M' Φ_c): the normalisation, within the span.
  for (int i = 0; i < m; ++i)
    for (int l = 0; l < m; ++l)
      E(C.modes[static_cast<std::size_t>(l)], i) -= 0.5 * Phi.col(C.modes[static_cast<std::size_t>(l)]).dot(Mc.col(i));
  d.domega = d.dlambda / (2.0 * C.omega);
  d.df = d.domega / kTwoPi;
  if (damping) {
    double tr_DdPhi = 0.0;
    for (int i = 0; i < m; ++i) tr_DdPhi += W.col(i).dot(E.col(i));
    d.dzeta = (tr_dD + 2.0 * tr_DdPhi) / (2.0 * m * C.omega) - C.zeta * d.domega / C.omega;
  }
  if (shapes) d.dY = s.Y * E;
  return d;
}

// What Nelson's method needs of one matched mode, once per evaluation: the regularised K − λM
// (row and column r replaced by the identity's) factorised, M φ and D φ.
struct NelsonMode {
  int r = 0;
  VectorXd Mphi, Dphi;
  std::unique_ptr<Eigen::SparseLU<SparseMatrix>> lu;
};

NelsonMode nelson_mode(const VectorXd& phi, double lambda, const SparseMatrix& M, const SparseMatrix& K, const SparseMatrix& D,
                       bool damping) {
  NelsonMode nmode;
  phi.cwiseAbs().maxCoeff(&nmode.r);
  const SparseMatrix A = K - lambda * M;
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<std::size_t>(A.nonZeros()) + 1);
  for (int j = 0; j < A.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(A, j); it; ++it)
      if (it.row() != nmode.r && it.col() != nmode.r) t.emplace_back(static_cast<int>(it.row()), static_cast<int>(it.col()), it.value());
  t.emplace_back(nmode.r, nmode.r, 1.0);
  SparseMatrix Ar(A.rows(), A.cols());
  Ar.setFromTriplets(t.begin(), t.end());
  nmode.lu = std::make_unique<Eigen::SparseLU<SparseMatrix>>();
  nmode.lu->compute(Ar);
  if (nmode.lu->info() != Eigen::Success)
    throw std::domain_error("ModalMisfit: Nelson's matrix K - lambda M is singular at a matched mode (a repeated eigenvalue?)");
  nmode.Mphi = M * phi;
  if (damping) nmode.Dphi = D * phi;
  return nmode;
}

// cluster_derivative's quantities from the cluster's own modes (the sparse path, header): the mean
// eigenvalue's derivative for any cluster; for a single mode also dφ by Nelson's method, and from
// it the damping ratio's and the station shape's.
ClusterDerivative nelson_derivative(const Spectrum& s, const Cluster& C, const NelsonMode* nmode, const MatrixXd& Cs,
                                    const SparseMatrix& dM, const SparseMatrix& dK, const SparseMatrix& dD, bool damping,
                                    bool shapes) {
  ClusterDerivative d;
  const int m = static_cast<int>(C.modes.size());
  for (int k : C.modes) {
    const VectorXd phi = s.Phi.col(k);
    d.dlambda += phi.dot(dK * phi - s.lambda[k] * (dM * phi)) / m;
  }
  d.domega = d.dlambda / (2.0 * C.omega);
  d.df = d.domega / kTwoPi;
  if (!damping && !shapes) return d;
  if (m != 1 || nmode == nullptr) throw std::logic_error("ModalMisfit: Nelson's method on a cluster (the dense path takes it)");
  const int k = C.modes.front();
  const VectorXd phi = s.Phi.col(k);
  const VectorXd dMphi = dM * phi;
  VectorXd F = -(dK * phi - s.lambda[k] * dMphi - d.dlambda * nmode->Mphi);
  F[nmode->r] = 0.0;
  const VectorXd v = nmode->lu->solve(F);
  const VectorXd dphi = v + (-nmode->Mphi.dot(v) - 0.5 * phi.dot(dMphi)) * phi;
  if (damping) {
    const double tr_dD = phi.dot(dD * phi);
    d.dzeta = (tr_dD + 2.0 * nmode->Dphi.dot(dphi)) / (2.0 * C.omega) - C.zeta * d.domega / C.omega;
  }
  if (shapes) d.dY = Cs * dphi;
  return d;
}

// The weighted residuals of the matched modes (frequency, damping ratio, unit station shape with
// its sign), the matches, and per measured mode what the shape derivatives need.
VectorXd modal_residuals(const Spectrum& s, const io::ModalData& data, const std::vector<VectorXd>& measured_shape,
                         int rows_per_mode, const std::vector<int>& partner, const std::vector<double>& mac_of,
                         std::vector<ShapeMatch>& shape, std::vector<ModalMisfit::Match>& matches) {
  const bool damping = data.has_damping(), shapes = data.has_shapes();
  const int nmeas = static_cast<int>(data.modes.size());
  const Eigen::Index ns = static_cast<Eigen::Index>(data.stations.size());
  VectorXd r(static_cast<Eigen::Index>(rows_per_mode) * nmeas);
  matches.clear();
  shape.assign(static_cast<std::size_t>(nmeas), {});
  for (int i = 0; i < nmeas; ++i) {
    const auto& md = data.modes[static_cast<std::size_t>(i)];
    const int f = partner[static_cast<std::size_t>(i)];
    const Cluster& C = s.of(f);
    const Eigen::Index row = static_cast<Eigen::Index>(i) * rows_per_mode;
    r[row] = (C.f - md.frequency_hz) / md.frequency_std_hz;
    if (damping) r[row + 1] = (C.zeta - md.damping_ratio) / md.damping_std;
    if (shapes) {
      const VectorXd& psim = measured_shape[static_cast<std::size_t>(i)];
      ShapeMatch& sm = shape[static_cast<std::size_t>(i)];
      project(C, psim, &sm.coef);
      const VectorXd p = C.Y * sm.coef;
      sm.pnorm = p.norm();
      if (!(sm.pnorm > 0)) throw std::domain_error("ModalMisfit: a matched model shape vanishes at the stations");
      sm.unit = p / sm.pnorm;
      sm.sign = psim.dot(sm.unit) < 0 ? -1.0 : 1.0;
      r.segment(row + (damping ? 2 : 1), ns) = (sm.sign * sm.unit - psim) / md.shape_std;
    }
    matches.push_back({i, f, static_cast<int>(C.modes.size()), mac_of[static_cast<std::size_t>(i)], C.f, C.zeta});
  }
  return r;
}

// ∂r/∂q: per parameter direction, the derivative of every matched cluster (cluster_derivative),
// then of each residual row.
// With `few` (the sparse path, header) the clusters' derivatives from their own modes
// (nelson_derivative), otherwise from every mode (cluster_derivative).
MatrixXd modal_jacobian(const StructuralModel& model, const Spectrum& s, const SparseMatrix& M, const SparseMatrix& K,
                        const SparseMatrix& D, const MatrixXd& Cs, bool few, const MatrixXd& dcdq, const io::ModalData& data,
                        int rows_per_mode, const std::vector<int>& partner, const std::vector<ShapeMatch>& shape) {
  const bool damping = data.has_damping(), shapes = data.has_shapes();
  const int nmeas = static_cast<int>(data.modes.size());
  const Eigen::Index ns = static_cast<Eigen::Index>(data.stations.size());
  const int n = model.ndof;
  const Eigen::Index P = dcdq.cols();
  MatrixXd jacobian = MatrixXd::Zero(static_cast<Eigen::Index>(rows_per_mode) * nmeas, P);
  // The clusters that carry a match, with what their derivatives need once per evaluation.
  std::vector<int> used;
  for (int i = 0; i < nmeas; ++i) {
    const int j = s.cluster_of[static_cast<std::size_t>(partner[static_cast<std::size_t>(i)])];
    if (std::find(used.begin(), used.end(), j) == used.end()) used.push_back(j);
  }
  std::vector<MatrixXd> W(used.size());  // Φᵀ D Φ_c, for tr(Φ_cᵀ D dΦ_c)
  std::vector<NelsonMode> nelson(used.size());
  if (few && (damping || shapes))
    for (std::size_t u = 0; u < used.size(); ++u) {
      const Cluster& C = s.cl[static_cast<std::size_t>(used[u])];
      nelson[u] = nelson_mode(s.Phi.col(C.modes.front()), s.lambda[C.modes.front()], M, K, D, damping);
    }
  if (damping && !few)
    for (std::size_t u = 0; u < used.size(); ++u) {
      const Cluster& C = s.cl[static_cast<std::size_t>(used[u])];
      MatrixXd DPc(n, static_cast<Eigen::Index>(C.modes.size()));
      for (std::size_t i = 0; i < C.modes.size(); ++i) DPc.col(static_cast<Eigen::Index>(i)) = D * s.Phi.col(C.modes[i]);
      W[u] = s.Phi.transpose() * DPc;
    }
  std::vector<ClusterDerivative> cd(used.size());
  for (Eigen::Index p = 0; p < P; ++p) {
    const VectorXd dc = dcdq.col(p);
    if (dc.cwiseAbs().maxCoeff() == 0.0) continue;
    const SparseMatrix dM = along(model.mass, dc, n);
    const SparseMatrix dK = along(model.stiffness, dc, n);
    const SparseMatrix dD = damping ? along(model.damping, dc, n) : SparseMatrix(n, n);
    for (std::size_t u = 0; u < used.size(); ++u) {
      const Cluster& C = s.cl[static_cast<std::size_t>(used[u])];
      cd[u] = few ? nelson_derivative(s, C, nelson[u].lu ? &nelson[u] : nullptr, Cs, dM, dK, dD, damping, shapes)
                  : cluster_derivative(s, C, W[u], dM, dK, dD, damping, shapes);
    }
    for (int i = 0; i < nmeas; ++i) {
      const auto& md = data.modes[static_cast<std::size_t>(i)];
      const int j = s.cluster_of[static_cast<std::size_t>(partner[static_cast<std::size_t>(i)])];
      const std::size_t u = static_cast<std::size_t>(std::find(used.begin(), used.end(), j) - used.begin());
      const ClusterDerivative& d = cd[u];
      const Eigen::Index row = static_cast<Eigen::Index>(i) * rows_per_mode;
      jacobian(row, p) = d.df / md.frequency_std_hz;
      if (damping) jacobian(row + 1, p) = d.dzeta / md.damping_std;
      if (shapes) {
        const ShapeMatch& sm = shape[static_cast<std::size_t>(i)];
        const VectorXd dp = d.dY * sm.coef;
        const VectorXd dph = (dp - sm.unit * sm.unit.dot(dp)) / sm.pnorm;
        jacobian.block(row + (damping ? 2 : 1), p, ns, 1) = sm.sign * dph / md.shape_std;
      }
    }
  }
  return jacobian;
}

}  // namespace

const ModalMisfit::Evaluation& ModalMisfit::evaluate(const VectorXd& q, bool derivatives) {
  if (have_last_ && last_.q.size() == q.size() && (last_.q.array() == q.array()).all() &&
      (last_.has_jacobian || !derivatives))
    return last_;
  have_last_ = false;
  if (q.size() != params_.size())
    throw std::invalid_argument("ModalMisfit: parameter vector of size " + std::to_string(q.size()) + ", expected " +
                                std::to_string(params_.size()));
  const int nmeas = static_cast<int>(data_.modes.size());

  VectorXd c;
  MatrixXd dcdq;
  params_.coefficients(q, c, dcdq);
  if (!c.allFinite()) throw std::domain_error("ModalMisfit: model coefficients are not finite at this q");
  const SparseMatrix M = model_.assemble(model_.mass, c);
  const SparseMatrix D = model_.assemble(model_.damping, c);
  const SparseMatrix K = model_.assemble(model_.stiffness, c);
  // The modes: the few the matching needs where that pays (header), else every one.
  const bool derivative_of_shapes = data_.has_shapes() || data_.has_damping();
  const int needed = nmeas + options_.extra_candidates + 1;  // the candidates and one above them
  NaturalModes nm;
  bool few = false;
  if (model_.ndof >= options_.sparse_from && 8 * (needed + 6) <= model_.ndof) {
    LowestModesOptions lo;
    lo.flexible = needed;
    lo.tolerance = options_.sparse_tolerance;
    try {
      nm = lowest_modes(M, K, lo);
      few = nm.omega.size() < model_.ndof;
    } catch (const LowestModesFailure&) {
      few = false;  // the dense solution below
    }
  }
  std::vector<double> mac_of;
  std::vector<int> partner;
  std::unique_ptr<Spectrum> s;
  for (int pass = 0; pass < 2; ++pass) {
    if (!few) nm = natural_modes(M, K);
    ++counters_.evaluations;
    if (few) ++counters_.sparse_evaluations;
    if (!nm.omega.allFinite() || !nm.vectors.allFinite())
      throw std::domain_error("ModalMisfit: the eigenproblem has no finite solution at this q");
    s = std::make_unique<Spectrum>(cluster_spectrum(nm, D, Cs_, nmeas, data_.has_shapes(), options_));
    partner = pair_modes(*s, data_, measured_shape_, mac_of);
    if (!few) break;
    // The sparse path holds where every matched cluster is complete among the computed modes and,
    // where shapes or damping are differentiated, a single mode (Nelson's method).
    const int last_cluster = s->cluster_of.back();
    bool holds = true;
    for (int f : partner) {
      const int j = s->cluster_of[static_cast<std::size_t>(f)];
      if (j == last_cluster || (derivative_of_shapes && s->cl[static_cast<std::size_t>(j)].modes.size() > 1)) holds = false;
    }
    if (holds) break;
    few = false;
  }

  Evaluation& e = last_;
  e.q = q;
  std::vector<ShapeMatch> shape;
  e.r = modal_residuals(*s, data_, measured_shape_, rows_per_mode_, partner, mac_of, shape, e.matches);
  e.J = 0.5 * e.r.squaredNorm();
  e.has_jacobian = false;
  e.jacobian.resize(0, 0);
  if (!std::isfinite(e.J)) throw std::domain_error("ModalMisfit: the misfit is not finite at this q");
  if (derivatives) {
    e.jacobian = modal_jacobian(model_, *s, M, K, D, Cs_, few, dcdq, data_, rows_per_mode_, partner, shape);
    e.has_jacobian = true;
    if (!e.jacobian.allFinite()) throw std::domain_error("ModalMisfit: the Jacobian is not finite at this q");
  }
  have_last_ = true;
  return e;
}

double ModalMisfit::residuals(const VectorXd& q, VectorXd& r, MatrixXd* jacobian) {
  const Evaluation& e = evaluate(q, jacobian != nullptr);
  r = e.r;
  if (jacobian) *jacobian = e.jacobian;
  return e.J;
}

double ModalMisfit::cost(const VectorXd& q) { return evaluate(q, false).J; }

double ModalMisfit::cost_and_gradient(const VectorXd& q, VectorXd& gradient) {
  const Evaluation& e = evaluate(q, true);
  gradient = e.jacobian.transpose() * e.r;
  return e.J;
}

double ModalMisfit::gauss_newton(const VectorXd& q, VectorXd& gradient, MatrixXd& H, MisfitProfile* profile) {
  const Evaluation& e = evaluate(q, true);
  gradient = e.jacobian.transpose() * e.r;
  H = e.jacobian.transpose() * e.jacobian;
  if (profile) {
    profile->t = {1.0};
    profile->misfit = {2.0 * e.J / static_cast<double>(std::max(1L, data_points()))};
  }
  return e.J;
}

Misfit::MisfitProfile ModalMisfit::misfit_profile(const VectorXd& q) {
  const Evaluation& e = evaluate(q, false);
  MisfitProfile p;
  p.t = {1.0};
  p.misfit = {2.0 * e.J / static_cast<double>(std::max(1L, data_points()))};
  return p;
}

VectorXd ModalMisfit::gauss_newton_product(const VectorXd& q, const VectorXd& v) {
  const Evaluation& e = evaluate(q, true);
  return e.jacobian.transpose() * (e.jacobian * v);
}

MatrixXd ModalMisfit::fisher(const VectorXd& q) {
  const Evaluation& e = evaluate(q, true);
  return e.jacobian.transpose() * e.jacobian;
}

std::vector<ModalMisfit::Match> ModalMisfit::matches(const VectorXd& q) { return evaluate(q, false).matches; }

}  // namespace scoleid::identify
