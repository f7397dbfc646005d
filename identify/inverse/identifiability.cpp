#include "scoleid/identify/inverse/identifiability.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace scoleid::identify {

FisherInformation& FisherInformation::operator+=(const FisherInformation& o) {
  if (F.size() == 0) F = MatrixXd::Zero(o.F.rows(), o.F.cols());
  F += o.F;
  chi2 += o.chi2;
  data_values += o.data_values;
  systematic += o.systematic;
  noise_std.insert(noise_std.end(), o.noise_std.begin(), o.noise_std.end());
  stated_noise = stated_noise && o.stated_noise;
  return *this;
}

FisherInformation fisher_information(Objective& obj, const std::vector<io::SensorSpec>& sensors, const VectorXd& q) {
  return fisher_information(obj.data(), obj.predict(q), obj.output_sensitivities(q), sensors);
}

FisherInformation fisher_information(const Measurements& data, const MatrixXd& Y, const MatrixXd& G,
                                     const std::vector<io::SensorSpec>& sensors) {
  FisherInformation id;
  const int P = static_cast<int>(G.cols()), ns = data.sensors();
  const auto N = static_cast<Eigen::Index>(data.t.size());
  // Noise level per sensor.
  bool from_scenario = true;
  for (int k = 0; k < ns; ++k) {
    double sd = static_cast<std::size_t>(k) < sensors.size() ? sensors[static_cast<std::size_t>(k)].noise_std : 0.0;
    if (!(sd > 0)) {
      from_scenario = false;
      const VectorXd r = Y.col(k) - data.z.col(k);
      const double dof = std::max<double>(1.0, static_cast<double>(N) - static_cast<double>(P) / ns);
      sd = std::sqrt(r.squaredNorm() / dof);
      if (!(sd > 0)) sd = 1e-300;
    }
    id.noise_std.push_back(sd);
  }
  id.stated_noise = from_scenario;
  MatrixXd& F = id.F;
  F = MatrixXd::Zero(P, P);
  id.chi2 = 0.0;
  for (Eigen::Index i = 0; i < N; ++i)
    for (int k = 0; k < ns; ++k) {
      const double w = 1.0 / (id.noise_std[static_cast<std::size_t>(k)] * id.noise_std[static_cast<std::size_t>(k)]);
      const Eigen::RowVectorXd g = G.row(i * ns + k);
      F += w * g.transpose() * g;
      const double r = Y(i, k) - data.z(i, k);
      id.chi2 += w * r * r;
    }
  id.data_values = static_cast<long>(N) * ns;
  // Residual energy counted as model error: beyond the upper end of the χ² band of the stated noise
  // (N ± 2√(2N): white noise alone reaches it one time in forty), or all of it with no stated noise.
  const double Nd = static_cast<double>(id.data_values);
  id.systematic = from_scenario ? std::max(0.0, id.chi2 - Nd - 2.0 * std::sqrt(2.0 * Nd)) : id.chi2;
  return id;
}

namespace {

// Directions the data cannot see (eigenvalues of the relative Fisher matrix below 1e-12 of the
// largest): every parameter with a sizeable share in them is flagged; the others get their bounds
// from the Fisher matrix restricted to them (i.e. with the flagged parameters held fixed). A
// parameter's share in them is the length of its unit vector projected on their span
// (√Σ_e v_ie², independent of how a repeated small eigenvalue's vectors are chosen); returned.
VectorXd unseen_directions(const Eigen::SelfAdjointEigenSolver<MatrixXd>& es, const VectorXd& q, Identifiability& id) {
  const int P = static_cast<int>(q.size());
  const double lmax = es.eigenvalues().maxCoeff();
  VectorXd unseen_share = VectorXd::Zero(P);
  for (int e = 0; e < P; ++e)
    if (!(es.eigenvalues()[e] > 1e-12 * lmax)) unseen_share += es.eigenvectors().col(e).cwiseAbs2();
  unseen_share = unseen_share.cwiseSqrt();
  for (int i = 0; i < P; ++i)
    if (unseen_share[i] > 0.1) {
      id.identifiable[static_cast<std::size_t>(i)] = false;
      id.reason[static_cast<std::size_t>(i)] = "loads a direction the data cannot see (Fisher eigenvalue below 1e-12 of the largest)";
    }
  {
    int k = 0;
    for (int e = 0; e < P; ++e)
      if (!(es.eigenvalues()[e] > 1e-12 * lmax)) ++k;
    if (k > 0 && k < P) {
      id.unseen.resize(P, k);
      MatrixXd Cr = MatrixXd::Zero(P, P);
      int c = 0;
      for (int e = 0; e < P; ++e) {
        const VectorXd v = es.eigenvectors().col(e);
        if (!(es.eigenvalues()[e] > 1e-12 * lmax)) id.unseen.col(c++) = v;
        else Cr += v * v.transpose() / es.eigenvalues()[e];
      }
      id.covariance_pinv = q.asDiagonal() * Cr * q.asDiagonal();
    }
  }
  return unseen_share;
}

// An unseen direction shared by exactly two parameters i, j (d log q = s (v_i, v_j)): the data fix
// the one combination it leaves unchanged, q_i / q_j^(v_i/v_j) (a free decay: EI/rho_A), which
// their reasons name.
void name_unseen_pairs(const Eigen::SelfAdjointEigenSolver<MatrixXd>& es, const std::vector<std::string>& names, Identifiability& id) {
  const int P = static_cast<int>(names.size());
  const double lmax = es.eigenvalues().maxCoeff();
  for (int e = 0; e < P; ++e) {
    if (es.eigenvalues()[e] > 1e-12 * lmax) continue;
    const VectorXd v = es.eigenvectors().col(e);
    std::vector<int> big;
    for (int i = 0; i < P; ++i)
      if (std::abs(v[i]) > 0.1) big.push_back(i);
    if (big.size() != 2) continue;
    const int i = big[0], j = big[1];
    const double k = v[i] / v[j];
    const std::string& ni = names[static_cast<std::size_t>(i)];
    const std::string& nj = names[static_cast<std::size_t>(j)];
    char comb[160];
    if (std::abs(k - 1.0) < 0.05) std::snprintf(comb, sizeof comb, "%s/%s", ni.c_str(), nj.c_str());
    else if (std::abs(k + 1.0) < 0.05) std::snprintf(comb, sizeof comb, "%s*%s", ni.c_str(), nj.c_str());
    else std::snprintf(comb, sizeof comb, "%s/%s^%.3g", ni.c_str(), nj.c_str(), k);
    for (int a : {i, j}) {
      const std::string& other = a == i ? nj : ni;
      id.reason[static_cast<std::size_t>(a)] = "moves with " + other +
                                               " along a direction the data cannot see (Fisher eigenvalue below 1e-12 of "
                                               "the largest): the data fix " + comb + " only";
    }
  }
}

// The std and resolution of the parameters the data see (id.identifiable so far), from the
// relative Fisher matrix Fr restricted to them; each flagged where either exceeds half its value,
// where the restricted matrix is singular too, or where its share in an unseen direction exceeds
// its relative std (docs/theory.md §8.1).
void seen_bounds(const MatrixXd& Fr, const VectorXd& q, double systematic, const VectorXd& unseen_share, Identifiability& id) {
  const int P = static_cast<int>(q.size());
  std::vector<int> keep;
  for (int i = 0; i < P; ++i)
    if (id.identifiable[static_cast<std::size_t>(i)]) keep.push_back(i);
  if (!keep.empty()) {
    const auto K = static_cast<Eigen::Index>(keep.size());
    MatrixXd Fk(K, K);
    for (Eigen::Index a = 0; a < K; ++a)
      for (Eigen::Index b = 0; b < K; ++b)
        Fk(a, b) = Fr(keep[static_cast<std::size_t>(a)], keep[static_cast<std::size_t>(b)]);
    const MatrixXd Ck = Fk.inverse();
    for (Eigen::Index a = 0; a < K; ++a)
      for (Eigen::Index b = 0; b < K; ++b) {
        const int i = keep[static_cast<std::size_t>(a)], j = keep[static_cast<std::size_t>(b)];
        id.covariance(i, j) = Ck(a, b) * q[i] * q[j];
      }
    for (Eigen::Index a = 0; a < K; ++a) {
      if (!(Ck(a, a) > 0.0) || !std::isfinite(Ck(a, a))) {  // the restricted matrix is singular too
        const int i = keep[static_cast<std::size_t>(a)];
        id.identifiable[static_cast<std::size_t>(i)] = false;
        id.reason[static_cast<std::size_t>(i)] = "the Fisher matrix of the parameters the data see is singular";
        continue;
      }
      const double rel = std::sqrt(Ck(a, a));
      const double rel_res = rel * std::sqrt(systematic);
      const int i = keep[static_cast<std::size_t>(a)];
      id.std[i] = rel * q[i];
      id.resolution[i] = rel_res * q[i];
      // more than 50 % relative uncertainty or resolution: not determined by these data
      if (!(rel < 0.5) || !(rel_res < 0.5)) {
        id.identifiable[static_cast<std::size_t>(i)] = false;
        char buf[160];
        std::snprintf(buf, sizeof buf, "relative std %.3g and relative resolution %.3g: above 0.5", rel, rel_res);
        id.reason[static_cast<std::size_t>(i)] = buf;
        continue;
      }
      // The std above holds the flagged parameters fixed. Along an unseen direction the estimate
      // is wherever the start and the optimiser's path left it — a relative change of order one
      // (a factor e) is as plausible as none — and a parameter with share s in that direction
      // moves by s along with it. Where s exceeds its relative std, the std would promise what the
      // data do not hold: that parameter is flagged too (docs/theory.md §8.1).
      // (Shares below 1e-6 are rounding in the eigenvectors, and move a parameter by less than that.)
      if (const double share = unseen_share[i]; share > std::max(rel, 1e-6)) {
        id.identifiable[static_cast<std::size_t>(i)] = false;
        char buf[200];
        std::snprintf(buf, sizeof buf,
                      "shares a direction the data cannot see (share %.3g in the Fisher eigenvectors below 1e-12 of the "
                      "largest, against its relative std %.3g)",
                      share, rel);
        id.reason[static_cast<std::size_t>(i)] = buf;
      }
    }
  }
}

}  // namespace

Identifiability identifiability_from(const FisherInformation& fi, const VectorXd& q, const std::vector<std::string>* names) {
  Identifiability id;
  const int P = static_cast<int>(q.size());
  const MatrixXd& F = fi.F;
  const double systematic = fi.systematic;
  id.chi2 = fi.chi2;
  id.data_values = fi.data_values;
  id.noise_std = fi.noise_std;
  id.noise_source = fi.stated_noise ? "scenario" : "residual";
  const MatrixXd Fr = q.asDiagonal() * F * q.asDiagonal();
  Eigen::SelfAdjointEigenSolver<MatrixXd> es(Fr);
  const double lmax = es.eigenvalues().maxCoeff(), lmin = es.eigenvalues().minCoeff();
  id.condition_number = lmin > 0 ? lmax / lmin : std::numeric_limits<double>::infinity();
  id.std = VectorXd::Constant(P, std::nan(""));
  id.resolution = VectorXd::Constant(P, std::nan(""));
  id.covariance = MatrixXd::Constant(P, P, std::nan(""));
  id.systematic = systematic;
  id.identifiable.assign(static_cast<std::size_t>(P), true);
  id.reason.assign(static_cast<std::size_t>(P), "");
  const VectorXd unseen_share = unseen_directions(es, q, id);
  if (names && static_cast<int>(names->size()) == P) name_unseen_pairs(es, *names, id);
  // Without a stated noise level σ comes from the residual with ν = N − P degrees of freedom; below
  // ν = 10 that estimate is not a scale (at ν = 10 the level is within a factor 1.75 at 95 %, at
  // ν = 1 within a factor 16), and neither is any std drawn from it.
  if (!fi.stated_noise && static_cast<double>(fi.data_values) - P < 10.0)
    for (int i = 0; i < P; ++i) {
      id.identifiable[static_cast<std::size_t>(i)] = false;
      id.reason[static_cast<std::size_t>(i)] =
          "no noise level stated and " + std::to_string(fi.data_values) + " data values for " + std::to_string(P) +
          " parameters: fewer than 10 left to estimate the noise from the residual";
    }
  seen_bounds(Fr, q, systematic, unseen_share, id);
  return id;
}

Identifiability analyse_identifiability(Objective& obj, const std::vector<io::SensorSpec>& sensors, const VectorXd& q) {
  return identifiability_from(fisher_information(obj, sensors, q), q);
}

}  // namespace scoleid::identify
