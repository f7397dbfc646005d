#include "scoleid/identify/inverse/modal_uncertainty.h"

#include <cmath>
#include <limits>

#include "scoleid/identify/fe/state_space.h"

namespace scoleid::identify {

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;

// Frequencies (Hz) and damping ratios of the elastic modes at q, lowest first: every one, or on a
// large model the lowest `wanted` (state_space.h).
struct Modes {
  VectorXd f, zeta;
};
Modes elastic_modes(const StructuralModel& model, const Parameterization& params, const VectorXd& q, int wanted) {
  VectorXd c;
  MatrixXd dcdq;
  params.coefficients(q, c, dcdq);
  const ModalModel mm = modal_model(model, c, wanted);
  std::vector<Eigen::Index> keep;
  for (Eigen::Index k = 0; k < mm.omega.size(); ++k)
    if (std::isfinite(mm.zeta[k])) keep.push_back(k);  // rigid-body modes have ζ = NaN
  Modes m;
  m.f.resize(static_cast<Eigen::Index>(keep.size()));
  m.zeta.resize(m.f.size());
  for (std::size_t j = 0; j < keep.size(); ++j) {
    m.f[static_cast<Eigen::Index>(j)] = mm.omega[keep[j]] / kTwoPi;
    m.zeta[static_cast<Eigen::Index>(j)] = mm.zeta[keep[j]];
  }
  return m;
}

// The propagated std and half-width of a derived quantity with gradient g (one row of J).
struct Propagated {
  double std = std::numeric_limits<double>::quiet_NaN(), half_width = std::numeric_limits<double>::quiet_NaN();
};
Propagated propagate(const VectorXd& g, const Identifiability& id, const UncertaintyInterval& iv) {
  Propagated out;
  const auto P = g.size();
  if (id.covariance.rows() != P) return out;
  double var = 0.0;
  for (Eigen::Index i = 0; i < P; ++i)
    for (Eigen::Index j = 0; j < P; ++j)
      if (g[i] != 0.0 && g[j] != 0.0 && std::isfinite(id.covariance(i, j))) var += g[i] * id.covariance(i, j) * g[j];
  out.std = std::sqrt(std::max(var, 0.0));
  if (iv.half_record_delta.size() != P) return out;  // no refit: no interval (interval.h)
  double hw = 2.0 * out.std * std::sqrt(1.0 + std::max(id.systematic, 0.0)) + std::abs(g.dot(iv.half_record_delta));
  for (const auto& t : iv.terms)
    if (t.shift.size() == P) hw += std::abs(g.dot(t.shift));
  if (iv.smoothing_delta.size() == P) hw += std::abs(g.dot(iv.smoothing_delta));
  out.half_width = hw;
  return out;
}

// The record's own frequency and damping of mode e (record_modes.h): m + J Δq + the freed
// coordinate's share, its std from the step's covariance; where it differs from the model's by
// more than `threshold` of that std, the miss plus twice the std widens the half-width.
void add_record_mode(const RecordModes& rec, ModalEstimate& e, const VectorXd& jf, const VectorXd& jz, double threshold) {
  const int j = rec.index_of(e.mode);
  const auto P = jf.size();
  if (j < 0 || rec.dq.size() != P || rec.covariance.rows() != P + 2 * static_cast<Eigen::Index>(rec.modes.size())) return;
  auto spread = [&](const VectorXd& h) {  // hᵀ C h over the finite entries
    double var = 0.0;
    for (Eigen::Index a = 0; a < h.size(); ++a)
      for (Eigen::Index b = 0; b < h.size(); ++b)
        if (h[a] != 0.0 && h[b] != 0.0 && std::isfinite(rec.covariance(a, b))) var += h[a] * rec.covariance(a, b) * h[b];
    return std::sqrt(std::max(var, 0.0));
  };
  VectorXd hf = VectorXd::Zero(rec.covariance.rows()), hz = hf;
  hf.head(P) = jf;
  hz.head(P) = jz;
  hf[P + 2 * j] = 0.5 * e.frequency_hz;
  hz[P + 2 * j + 1] = 1.0;
  const double df = jf.dot(rec.dq) + 0.5 * e.frequency_hz * rec.eps[j];
  const double dz = jz.dot(rec.dq) + rec.eta[j];
  const double sf = spread(hf), sz = spread(hz);
  if (!std::isfinite(df) || !std::isfinite(dz) || !(sf > 0) || !(sz > 0)) return;
  e.record_frequency_hz = e.frequency_hz + df;
  e.record_frequency_std_hz = sf;
  e.record_damping_ratio = e.damping_ratio + dz;
  e.record_damping_std = sz;
  if (std::abs(df) > threshold * sf) {
    e.frequency_model_form_hz = std::abs(df) + 2.0 * sf;
    if (std::isfinite(e.frequency_half_width_hz)) e.frequency_half_width_hz += e.frequency_model_form_hz;
  }
  if (std::abs(dz) > threshold * sz) {
    e.damping_model_form = std::abs(dz) + 2.0 * sz;
    if (std::isfinite(e.damping_half_width)) e.damping_half_width += e.damping_model_form;
  }
}

}  // namespace

std::vector<ModalEstimate> modal_estimates(const StructuralModel& model, const Parameterization& params, const VectorXd& q,
                                           const Identifiability& ident, const UncertaintyInterval& interval,
                                           const ModalUncertaintyOptions& o) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Modes m0 = elastic_modes(model, params, q, o.max_modes + 1);  // and the next one's gap
  Eigen::Index n = std::min<Eigen::Index>(m0.f.size(), o.max_modes);
  if (o.max_frequency_hz > 0)
    while (n > 0 && !(m0.f[n - 1] < o.max_frequency_hz)) --n;
  std::vector<ModalEstimate> out(static_cast<std::size_t>(n));
  for (Eigen::Index k = 0; k < n; ++k) {
    auto& e = out[static_cast<std::size_t>(k)];
    e.mode = static_cast<int>(k) + 1;
    e.frequency_hz = m0.f[k];
    e.damping_ratio = m0.zeta[k];
    e.frequency_std_hz = e.frequency_half_width_hz = e.damping_std = e.damping_half_width = nan;
  }
  if (n == 0) return out;
  const auto P = q.size();
  const bool assessed = ident.std.size() == P && ident.covariance.rows() == P;
  if (!assessed) {
    for (auto& e : out) e.note = "no parameter uncertainty (run without the identifiability assessment)";
    return out;
  }
  // J by central differences, the modes matched by their order.
  MatrixXd Jf(n, P), Jz(n, P);
  bool reordered = false;
  for (Eigen::Index i = 0; i < P; ++i) {
    const double h = o.relative_step * (q[i] != 0.0 ? std::abs(q[i]) : 1.0);
    VectorXd qp = q, qm = q;
    qp[i] += h;
    qm[i] -= h;
    const Modes mp = elastic_modes(model, params, qp, o.max_modes),
                mm = elastic_modes(model, params, qm, o.max_modes);
    if (mp.f.size() < n || mm.f.size() < n) {
      reordered = true;
      break;
    }
    Jf.col(i) = (mp.f.head(n) - mm.f.head(n)) / (2.0 * h);
    Jz.col(i) = (mp.zeta.head(n) - mm.zeta.head(n)) / (2.0 * h);
  }
  for (Eigen::Index k = 0; k < n; ++k) {
    auto& e = out[static_cast<std::size_t>(k)];
    if (reordered) {
      e.note = "a parameter's perturbation changed the number of elastic modes";
      continue;
    }
    // Close neighbours: their order can swap within the difference step.
    double gap = std::numeric_limits<double>::infinity();
    if (k > 0) gap = std::min(gap, m0.f[k] - m0.f[k - 1]);
    if (k + 1 < m0.f.size()) gap = std::min(gap, m0.f[k + 1] - m0.f[k]);
    if (!(gap > 1e-3 * m0.f[k])) {
      e.note = "a neighbouring mode lies within 0.1 % of it: the two are not told apart by their order";
      continue;
    }
    // A mode resting on a parameter the data do not hold gets no uncertainty.
    std::string flagged;
    for (Eigen::Index i = 0; i < P; ++i) {
      const double rel = std::max(std::abs(Jf(k, i)) / std::max(m0.f[k], 1e-300),
                                  std::abs(Jz(k, i)) / std::max(std::abs(m0.zeta[k]), 1e-300) * (m0.zeta[k] != 0.0 ? 1.0 : 0.0)) *
                         std::abs(q[i]);
      const bool seen = static_cast<std::size_t>(i) < ident.identifiable.size() && ident.identifiable[static_cast<std::size_t>(i)] &&
                        std::isfinite(ident.covariance(i, i));
      if (rel > 1e-8 && !seen) flagged += (flagged.empty() ? "" : " and ") + params.names()[static_cast<std::size_t>(i)];
    }
    // Unless it rests on them only through what the data fix: its log-q gradients orthogonal to
    // every unseen direction (a free decay's frequencies and damping ratios depend on EI/rho_A,
    // not on EI and rho_A apart); then its variance is gᵀ C⁺ g (identifiability.h).
    bool through_fixed = false;
    if (!flagged.empty() && ident.unseen.rows() == P && ident.covariance_pinv.rows() == P) {
      const VectorXd df = Jf.row(k).transpose().cwiseProduct(q) / std::max(m0.f[k], 1e-300);
      const VectorXd dz = m0.zeta[k] != 0.0 ? VectorXd(Jz.row(k).transpose().cwiseProduct(q) / std::abs(m0.zeta[k]))
                                            : VectorXd(VectorXd::Zero(P));
      through_fixed = (ident.unseen.transpose() * df).cwiseAbs().maxCoeff() <= 1e-6 * std::max(df.norm(), 1e-300) &&
                      (ident.unseen.transpose() * dz).cwiseAbs().maxCoeff() <= 1e-6 * std::max(dz.norm(), 1e-300);
      // and every flagged parameter it reads is flagged for the unseen direction alone
      for (Eigen::Index i = 0; i < P && through_fixed; ++i) {
        const bool seen = static_cast<std::size_t>(i) < ident.identifiable.size() && ident.identifiable[static_cast<std::size_t>(i)];
        if (!seen && ident.unseen.row(i).norm() <= 0.1 && (std::abs(df[i]) > 1e-8 || std::abs(dz[i]) > 1e-8)) through_fixed = false;
      }
    }
    if (!flagged.empty() && !through_fixed) {
      e.note = "depends on " + flagged + (flagged.find(" and ") == std::string::npos ? ", which is" : ", which are") +
               " not identifiable";
      continue;
    }
    Identifiability pinv;
    if (through_fixed) {
      pinv = ident;
      pinv.covariance = ident.covariance_pinv;
    }
    const Identifiability& use = through_fixed ? pinv : ident;
    const Propagated pf = propagate(Jf.row(k).transpose(), use, interval);
    const Propagated pz = propagate(Jz.row(k).transpose(), use, interval);
    e.frequency_std_hz = pf.std;
    e.frequency_half_width_hz = pf.half_width;
    e.damping_std = pz.std;
    e.damping_half_width = pz.half_width;
    if (!std::isfinite(pf.half_width)) e.note = "no half-record refit: interval not assessed";
    else if (through_fixed) e.note = "from what the data fix (" + flagged + " not identifiable apart)";
    if (o.record) add_record_mode(*o.record, e, Jf.row(k).transpose(), Jz.row(k).transpose(), o.model_form_threshold);
  }
  return out;
}

MatrixXd correlation(const Identifiability& ident) {
  const MatrixXd& C = ident.covariance;
  MatrixXd R = MatrixXd::Constant(C.rows(), C.cols(), std::numeric_limits<double>::quiet_NaN());
  for (Eigen::Index i = 0; i < C.rows(); ++i)
    for (Eigen::Index j = 0; j < C.cols(); ++j)
      if (C(i, i) > 0 && C(j, j) > 0 && std::isfinite(C(i, j))) R(i, j) = C(i, j) / std::sqrt(C(i, i) * C(j, j));
  return R;
}

}  // namespace scoleid::identify
