#include "scoleid/identify/inverse/spectral_start.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

#include <unsupported/Eigen/FFT>

#include "scoleid/identify/fe/state_space.h"

namespace scoleid::identify {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr std::size_t kMaxSamples = std::size_t{1} << 20;  // the first 2^20 samples are plenty for a peak

// log f of the lowest `n` elastic modes at q (fewer if the model has fewer).
VectorXd log_frequencies(const StructuralModel& model, const Parameterization& params, const VectorXd& q, Eigen::Index n) {
  VectorXd c;
  MatrixXd dcdq;
  params.coefficients(q, c, dcdq);
  const ModalModel mm = modal_model(model, c);
  std::vector<double> f;
  for (Eigen::Index k = 0; k < mm.omega.size() && static_cast<Eigen::Index>(f.size()) < n; ++k)
    if (std::isfinite(mm.zeta[k]) && mm.omega[k] > 0) f.push_back(std::log(mm.omega[k]));
  return Eigen::Map<VectorXd>(f.data(), static_cast<Eigen::Index>(f.size()));
}

}  // namespace

std::optional<double> dominant_frequency(const std::vector<double>& t, const MatrixXd& values) {
  const std::size_t N = std::min<std::size_t>(t.size(), kMaxSamples);
  if (N < 16 || values.rows() < static_cast<Eigen::Index>(N)) return std::nullopt;
  const double dt = (t[N - 1] - t[0]) / static_cast<double>(N - 1);
  if (!(dt > 0)) return std::nullopt;
  std::size_t nfft = 1;
  while (nfft < 2 * N) nfft <<= 1;  // zero-padded twice over: the peak between bins
  Eigen::FFT<double> fft;
  std::vector<double> power(nfft / 2 + 1, 0.0), x(nfft);
  std::vector<std::complex<double>> X;
  for (Eigen::Index k = 0; k < values.cols(); ++k) {
    double mean = 0.0;
    for (std::size_t i = 0; i < N; ++i) mean += values(static_cast<Eigen::Index>(i), k) / static_cast<double>(N);
    std::fill(x.begin(), x.end(), 0.0);
    for (std::size_t i = 0; i < N; ++i) {
      const double hann = 0.5 - 0.5 * std::cos(2.0 * kPi * static_cast<double>(i) / static_cast<double>(N - 1));
      x[i] = hann * (values(static_cast<Eigen::Index>(i), k) - mean);
    }
    fft.fwd(X, x);
    double total = 0.0;
    for (std::size_t b = 1; b < power.size(); ++b) total += std::norm(X[b]);
    if (!(total > 0) || !std::isfinite(total)) continue;
    for (std::size_t b = 1; b < power.size(); ++b) power[b] += std::norm(X[b]) / total;
  }
  const double df = 1.0 / (static_cast<double>(nfft) * dt), T = dt * static_cast<double>(N - 1);
  // At least four cycles in the record, and clear of the window's main lobe about zero.
  const auto first = static_cast<std::size_t>(std::ceil(4.0 / T / df));
  std::size_t best = 0;
  for (std::size_t b = std::max<std::size_t>(first, 2); b + 1 < power.size(); ++b)
    if (power[b] > power[b - 1] && power[b] >= power[b + 1] && (best == 0 || power[b] > power[best])) best = b;
  if (best == 0 || !(power[best] > 0)) return std::nullopt;
  // The parabola through the peak's three log-power bins.
  const double a = std::log(power[best - 1]), b = std::log(power[best]), c = std::log(power[best + 1]);
  const double denom = a - 2.0 * b + c;
  const double shift = denom < 0 ? 0.5 * (a - c) / denom : 0.0;
  return (static_cast<double>(best) + std::clamp(shift, -0.5, 0.5)) * df;
}

Spectrum power_spectrum(const std::vector<double>& t, const MatrixXd& values) {
  Spectrum out;
  const std::size_t N = std::min<std::size_t>(t.size(), kMaxSamples);
  if (N < 4 || values.rows() < static_cast<Eigen::Index>(N)) return out;
  const double dt = (t[N - 1] - t[0]) / static_cast<double>(N - 1);
  if (!(dt > 0)) return out;
  const std::size_t bins = N / 2;
  out.f.resize(bins);
  for (std::size_t b = 0; b < bins; ++b) out.f[b] = static_cast<double>(b + 1) / (static_cast<double>(N) * dt);
  out.psd = MatrixXd::Zero(static_cast<Eigen::Index>(bins), values.cols());
  Eigen::FFT<double> fft;
  std::vector<double> x(N), w(N);
  double w2 = 0.0;
  for (std::size_t i = 0; i < N; ++i) {
    w[i] = 0.5 - 0.5 * std::cos(2.0 * kPi * static_cast<double>(i) / static_cast<double>(N - 1));
    w2 += w[i] * w[i];
  }
  std::vector<std::complex<double>> X;
  for (Eigen::Index k = 0; k < values.cols(); ++k) {
    double mean = 0.0;
    for (std::size_t i = 0; i < N; ++i) mean += values(static_cast<Eigen::Index>(i), k) / static_cast<double>(N);
    for (std::size_t i = 0; i < N; ++i) x[i] = w[i] * (values(static_cast<Eigen::Index>(i), k) - mean);
    fft.fwd(X, x);
    for (std::size_t b = 0; b < bins; ++b) out.psd(static_cast<Eigen::Index>(b), k) = 2.0 * std::norm(X[b + 1]) * dt / w2;
  }
  return out;
}

SpectralStart spectral_start(const StructuralModel& model, const Parameterization& params, const VectorXd& q0,
                             const Measurements& data, const MatrixXd& predicted) {
  SpectralStart out;
  const auto fd = dominant_frequency(data.t, data.z);
  const auto fm = dominant_frequency(data.t, predicted);
  if (!fd || !fm) {
    out.note = !fd ? "the record has no spectral peak of four cycles or more" : "the model's response at the start has no spectral peak";
    return out;
  }
  out.data_hz = *fd;
  out.model_hz = *fm;
  const double log_r = std::log(*fd / *fm);
  const VectorXd f0 = log_frequencies(model, params, q0, 3);
  const Eigen::Index n = f0.size(), P = q0.size();
  if (n == 0 || P == 0) {
    out.note = "the model has no elastic mode";
    return out;
  }
  MatrixXd J(n, P);
  const double h = 1e-4;
  for (Eigen::Index i = 0; i < P; ++i) {
    VectorXd qp = q0, qm = q0;
    qp[i] *= std::exp(h);
    qm[i] *= std::exp(-h);
    const VectorXd fp = log_frequencies(model, params, qp, n), fmn = log_frequencies(model, params, qm, n);
    if (fp.size() != n || fmn.size() != n) {
      out.note = "a parameter's change alters the number of elastic modes";
      return out;
    }
    J.col(i) = (fp - fmn) / (2.0 * h);
  }
  const MatrixXd JJ = J * J.transpose();
  const double scale = JJ.diagonal().maxCoeff();
  if (!(scale > 0)) {
    out.note = "no estimated parameter moves the model's frequencies";
    return out;
  }
  const VectorXd rhs = VectorXd::Constant(n, log_r);
  const VectorXd delta = J.transpose() * (JJ + 1e-10 * scale * MatrixXd::Identity(n, n)).ldlt().solve(rhs);
  if (!delta.allFinite()) {
    out.note = "the frequency change cannot be solved for";
    return out;
  }
  out.q = q0.array() * delta.array().exp();
  return out;
}

}  // namespace scoleid::identify
