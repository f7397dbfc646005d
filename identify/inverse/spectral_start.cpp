#include "scoleid/identify/inverse/spectral_start.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
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
  const ModalModel mm = modal_model(model, c, static_cast<int>(n));
  std::vector<double> f;
  for (Eigen::Index k = 0; k < mm.omega.size() && static_cast<Eigen::Index>(f.size()) < n; ++k)
    if (std::isfinite(mm.zeta[k]) && mm.omega[k] > 0) f.push_back(std::log(mm.omega[k]));
  return Eigen::Map<VectorXd>(f.data(), static_cast<Eigen::Index>(f.size()));
}

// The sensors' Hann-windowed periodograms, each normalised by its total power, summed; zero-padded
// twice over. `first` is the lowest bin with four cycles in the record, clear of the window's
// main lobe about zero.
struct SummedSpectrum {
  std::vector<double> power;
  double df = 0.0;
  std::size_t first = 0;
};

std::optional<SummedSpectrum> summed_spectrum(const std::vector<double>& t, const MatrixXd& values) {
  const std::size_t N = std::min<std::size_t>(t.size(), kMaxSamples);
  if (N < 16 || values.rows() < static_cast<Eigen::Index>(N)) return std::nullopt;
  const double dt = (t[N - 1] - t[0]) / static_cast<double>(N - 1);
  if (!(dt > 0)) return std::nullopt;
  std::size_t nfft = 1;
  while (nfft < 2 * N) nfft <<= 1;  // zero-padded twice over: the peak between bins
  Eigen::FFT<double> fft;
  SummedSpectrum s;
  s.power.assign(nfft / 2 + 1, 0.0);
  std::vector<double> x(nfft);
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
    for (std::size_t b = 1; b < s.power.size(); ++b) total += std::norm(X[b]);
    if (!(total > 0) || !std::isfinite(total)) continue;
    for (std::size_t b = 1; b < s.power.size(); ++b) s.power[b] += std::norm(X[b]) / total;
  }
  s.df = 1.0 / (static_cast<double>(nfft) * dt);
  const double T = dt * static_cast<double>(N - 1);
  s.first = std::max<std::size_t>(static_cast<std::size_t>(std::ceil(4.0 / T / s.df)), 2);
  return s;
}

// The peak at bin b refined by the parabola through its three log-power bins.
double refined(const SummedSpectrum& s, std::size_t b) {
  const double a = std::log(s.power[b - 1]), c0 = std::log(s.power[b]), c = std::log(s.power[b + 1]);
  const double denom = a - 2.0 * c0 + c;
  const double shift = denom < 0 ? 0.5 * (a - c) / denom : 0.0;
  return (static_cast<double>(b) + std::clamp(shift, -0.5, 0.5)) * s.df;
}

}  // namespace

std::optional<double> dominant_frequency(const std::vector<double>& t, const MatrixXd& values) {
  const auto s = summed_spectrum(t, values);
  if (!s) return std::nullopt;
  const auto& power = s->power;
  std::size_t best = 0;
  for (std::size_t b = s->first; b + 1 < power.size(); ++b)
    if (power[b] > power[b - 1] && power[b] >= power[b + 1] && (best == 0 || power[b] > power[best])) best = b;
  if (best == 0 || !(power[best] > 0) || !(power[best - 1] > 0) || !(power[best + 1] > 0)) return std::nullopt;
  return refined(*s, best);
}

std::vector<SpectralPeak> spectral_peaks(const std::vector<double>& t, const MatrixXd& values, std::size_t max_peaks) {
  std::vector<SpectralPeak> out;
  const auto s = summed_spectrum(t, values);
  if (!s) return out;
  const auto& power = s->power;
  const std::size_t n = power.size();
  std::vector<SpectralPeak> all;
  for (std::size_t b = s->first; b + 1 < n; ++b) {
    if (!(power[b] > power[b - 1] && power[b] >= power[b + 1] && power[b - 1] > 0 && power[b + 1] > 0)) continue;
    // the largest within ±3 % of its frequency (at least ±2 bins): not a ripple on a peak's skirt
    const auto w = std::max<std::size_t>(2, static_cast<std::size_t>(0.03 * static_cast<double>(b)));
    bool largest = true;
    for (std::size_t i = b > w ? b - w : 0; i <= std::min(n - 1, b + w) && largest; ++i)
      if (i != b && power[i] > power[b]) largest = false;
    if (largest) all.push_back({refined(*s, b), power[b]});
  }
  if (all.empty()) return out;
  std::sort(all.begin(), all.end(), [](const SpectralPeak& a, const SpectralPeak& b) { return a.power > b.power; });
  for (const auto& pk : all)
    if (pk.power >= 1e-3 * all.front().power && out.size() < max_peaks) out.push_back(pk);
  return out;
}

std::optional<PeakMatch> match_peaks(const std::vector<SpectralPeak>& data, const std::vector<SpectralPeak>& model) {
  constexpr double kTol = 0.05, kMaxShift = 10.0;
  std::optional<PeakMatch> best;
  double best_score = 0.0;
  for (const auto& dj : data)
    for (const auto& mi : model) {
      const double r = dj.f / mi.f;
      if (!(r >= 1.0 / kMaxShift && r <= kMaxShift)) continue;
      double score = 0.0, sum_w = 0.0, sum_wlog = 0.0, strongest = 0.0;
      PeakMatch m;
      for (const auto& mk : model) {
        const SpectralPeak* near = nullptr;
        for (const auto& dl : data)
          if (!near || std::abs(std::log(r * mk.f / dl.f)) < std::abs(std::log(r * mk.f / near->f))) near = &dl;
        if (!near || !(std::abs(std::log(r * mk.f / near->f)) < kTol)) continue;
        const double w = std::sqrt(mk.power * near->power);
        score += w;
        sum_w += w;
        sum_wlog += w * std::log(near->f / mk.f);
        ++m.pairs;
        if (w > strongest) strongest = w, m.data_hz = near->f, m.model_hz = mk.f;
      }
      // the shift that lines up the most peaks; between as many, the stronger; between equals, the smaller
      const bool more = best && m.pairs > best->pairs, as_many = best && m.pairs == best->pairs;
      const bool better = !best || more ||
                          (as_many && (score > best_score * (1 + 1e-9) ||
                                       (score >= best_score * (1 - 1e-9) && std::abs(std::log(r)) < std::abs(std::log(best->ratio)))));
      if (m.pairs > 0 && better) {
        m.ratio = std::exp(sum_wlog / sum_w);
        best = m;
        best_score = score;
      }
    }
  return best;
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
  const auto pd = spectral_peaks(data.t, data.z), pm = spectral_peaks(data.t, predicted);
  if (pd.empty() || pm.empty()) {
    out.note = pd.empty() ? "the record has no spectral peak of four cycles or more" : "the model's response at the start has no spectral peak";
    return out;
  }
  const auto match = match_peaks(pd, pm);
  if (!match) {
    out.note = "no shift within a factor 10 lines the model's peaks up with the record's";
    return out;
  }
  out.data_hz = match->data_hz;
  out.model_hz = match->model_hz;
  out.ratio = match->ratio;
  out.pairs = match->pairs;
  const double log_r = std::log(match->ratio);
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
  // Nearly dependent rows of J (two modes that move alike but not quite) can ask a parameter for a
  // change far beyond the frequencies' own: such a start is a guess of the solve, not of the record.
  const double most = delta.cwiseAbs().maxCoeff();
  if (most > 3.0 * std::abs(log_r) + 1e-12) {
    char b[200];
    std::snprintf(b, sizeof b, "lining the peaks up (x%.4g) would move a parameter by a factor %.3g: not used", match->ratio,
                  std::exp(most));
    out.note = b;
    return out;
  }
  out.q = q0.array() * delta.array().exp();
  return out;
}

}  // namespace scoleid::identify
