#include "scoleid/identify/inverse/record_modes.h"

#include <chrono>
#include <cmath>
#include <limits>

#include <Eigen/SVD>

#include "scoleid/identify/fe/state_space.h"

namespace scoleid::identify {

int RecordModes::index_of(int mode) const {
  for (std::size_t j = 0; j < modes.size(); ++j)
    if (modes[j] == mode) return static_cast<int>(j);
  return -1;
}

RecordModes record_modes(Objective& obj, const StructuralModel& model, const Parameterization& params, const VectorXd& q,
                         const MatrixXd& Y, const std::vector<double>& noise_std, const std::vector<bool>& kept,
                         const RecordModesOptions& o) {
  const auto started = std::chrono::steady_clock::now();
  RecordModes out;
  const auto P = q.size();
  const Measurements& data = obj.data();
  const int ns = data.sensors();
  if (Y.rows() != data.z.rows() || Y.cols() != ns || static_cast<Eigen::Index>(kept.size()) != P || !(o.f_hi_hz > 0))
    return out;
  VectorXd c;
  MatrixXd dcdq;
  params.coefficients(q, c, dcdq);
  const ModalModel mm = modal_model(model, c, o.max_modes);
  // The elastic modes (rigid-body ones have ζ = NaN), numbered as modal_estimates numbers them.
  std::vector<Objective::RankOneDirection> dirs;
  int elastic = 0;
  for (Eigen::Index k = 0; k < mm.omega.size() && elastic < o.max_modes; ++k) {
    if (!std::isfinite(mm.zeta[k])) continue;
    ++elastic;
    const double f = mm.omega[k] / (2.0 * M_PI);
    if (f < o.f_lo_hz || f > o.f_hi_hz) continue;
    out.modes.push_back(elastic);
    const VectorXd w = mm.mass_shapes.col(k);
    dirs.push_back({w, 0.0, mm.omega[k] * mm.omega[k]});  // ε: ∂K = λ w wᵀ
    dirs.push_back({w, 2.0 * mm.omega[k], 0.0});          // η: ∂D = 2ω w wᵀ
  }
  if (out.modes.empty()) return out;
  // G and its weighted copy and singular vectors are held at once: a record too long for that
  // budget is not assessed.
  if (static_cast<double>(data.t.size()) * ns * static_cast<double>(P + static_cast<Eigen::Index>(dirs.size())) > kMaxValues) return {};
  const MatrixXd G = obj.output_sensitivities_with(q, dirs);
  if (G.cols() != P + static_cast<Eigen::Index>(dirs.size())) return {};
  // The columns in the step: the kept parameters, then every direction.
  std::vector<Eigen::Index> cols;
  for (Eigen::Index i = 0; i < P; ++i)
    if (kept[static_cast<std::size_t>(i)]) cols.push_back(i);
  for (Eigen::Index j = 0; j < static_cast<Eigen::Index>(dirs.size()); ++j) cols.push_back(P + j);
  const auto n = static_cast<Eigen::Index>(cols.size());
  MatrixXd Gk(G.rows(), n);
  for (Eigen::Index a = 0; a < n; ++a) Gk.col(a) = G.col(cols[static_cast<std::size_t>(a)]);
  VectorXd w(G.rows()), r(G.rows());
  for (Eigen::Index row = 0; row < G.rows(); ++row) {
    const auto k = static_cast<std::size_t>(row % ns);
    const double sd = k < noise_std.size() ? noise_std[k] : 0.0;
    w[row] = sd > 0 && std::isfinite(sd) ? 1.0 / (sd * sd) : 0.0;
    const Eigen::Index i = row / ns, s = row % ns;
    r[row] = data.z(i, s) - Y(i, s);
    if (!std::isfinite(r[row])) w[row] = r[row] = 0.0;
  }
  if (!Gk.allFinite()) return {};
  // The weighted, column-scaled sensitivities B = W^½ G S, solved by their singular values (not
  // the normal equations, whose condition is the square of B's): singular values below 10⁻⁶ of the
  // largest dropped (the near-redundant directions, e.g. every mode's ε against the parameters'
  // common frequency scale).
  VectorXd scale(n);
  MatrixXd B = w.cwiseSqrt().asDiagonal() * Gk;
  for (Eigen::Index a = 0; a < n; ++a) {
    const double norm = B.col(a).norm();
    scale[a] = norm > 0 ? 1.0 / norm : 0.0;
    B.col(a) *= scale[a];
  }
  const Eigen::BDCSVD<MatrixXd> svd(B, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const VectorXd& sv = svd.singularValues();
  if (!(sv.size() > 0 && sv[0] > 0)) return {};
  VectorXd inv = VectorXd::Zero(sv.size());
  for (Eigen::Index a = 0; a < sv.size(); ++a)
    if (sv[a] > 1e-6 * sv[0]) inv[a] = 1.0 / sv[a];
  const MatrixXd& V = svd.matrixV();
  const VectorXd theta = scale.asDiagonal() * (V * inv.asDiagonal() * (svd.matrixU().transpose() * w.cwiseSqrt().cwiseProduct(r)));
  const MatrixXd Ainv = scale.asDiagonal() * (V * inv.cwiseAbs2().asDiagonal() * V.transpose()) * scale.asDiagonal();
  const MatrixXd C = Ainv / (o.information_scale > 0 ? o.information_scale : 1.0);
  const auto m = static_cast<Eigen::Index>(dirs.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.dq = VectorXd::Zero(P);
  out.covariance = MatrixXd::Constant(P + m, P + m, nan);
  for (Eigen::Index a = 0; a < n; ++a) {  // each step column's place: cols[a]
    const Eigen::Index ia = cols[static_cast<std::size_t>(a)];
    if (ia < P) out.dq[ia] = theta[a];
    for (Eigen::Index b = 0; b < n; ++b) out.covariance(ia, cols[static_cast<std::size_t>(b)]) = C(a, b);
  }
  out.eps.resize(static_cast<Eigen::Index>(out.modes.size()));
  out.eta.resize(out.eps.size());
  for (Eigen::Index j = 0; j < out.eps.size(); ++j) {
    out.eps[j] = theta[n - m + 2 * j];
    out.eta[j] = theta[n - m + 2 * j + 1];
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return out;
}

}  // namespace scoleid::identify
