#include "scoleid/identify/run/residual_bands.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>

#include <unsupported/Eigen/FFT>

namespace scoleid::identify {

namespace {

std::string percent(double s) {
  char b[32];
  std::snprintf(b, sizeof b, "%.0f %%", 100.0 * s);
  return b;
}

std::string hz(double f) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", f);
  return b;
}

// The bands: each mode's [f − w, f + w], w = max(3/T, 5 ζ f), the gaps between, up to Nyquist.
std::vector<ResidualBands::Band> band_edges(const std::vector<ModalEstimate>& modes, double T, double nyquist) {
  std::vector<ModalEstimate> m;
  for (const auto& e : modes)
    if (e.frequency_hz > 0 && e.frequency_hz < nyquist) m.push_back(e);
  std::sort(m.begin(), m.end(), [](const ModalEstimate& a, const ModalEstimate& b) { return a.frequency_hz < b.frequency_hz; });
  std::vector<ResidualBands::Band> bands;
  auto add = [&](double from, double to, const std::string& holds, int mode) {
    if (to > from) bands.push_back({from, to, holds, mode, {}, 0.0});
  };
  if (m.empty()) {
    add(0.0, nyquist, "whole record", 0);
    return bands;
  }
  std::vector<double> lo(m.size()), hi(m.size());
  for (std::size_t k = 0; k < m.size(); ++k) {
    const double zeta = std::isfinite(m[k].damping_ratio) ? std::max(0.0, m[k].damping_ratio) : 0.0;
    const double w = std::max(3.0 / T, 5.0 * zeta * m[k].frequency_hz);
    lo[k] = std::max(0.0, m[k].frequency_hz - w);
    hi[k] = std::min(nyquist, m[k].frequency_hz + w);
  }
  for (std::size_t k = 0; k + 1 < m.size(); ++k)
    if (hi[k] > lo[k + 1]) hi[k] = lo[k + 1] = 0.5 * (m[k].frequency_hz + m[k + 1].frequency_hz);
  add(0.0, lo[0], "below mode " + std::to_string(m[0].mode), 0);
  for (std::size_t k = 0; k < m.size(); ++k) {
    add(lo[k], hi[k], "mode " + std::to_string(m[k].mode), m[k].mode);
    if (k + 1 < m.size())
      add(hi[k], lo[k + 1], "between modes " + std::to_string(m[k].mode) + " and " + std::to_string(m[k + 1].mode), 0);
  }
  add(hi.back(), nyquist, "above mode " + std::to_string(m.back().mode), 0);
  return bands;
}

// Each residual column's power by band (a bin on an edge goes to the band it opens), and each
// measured column's mean square in `record`.
std::vector<std::vector<double>> band_power(const Eigen::MatrixXd& measured, const Eigen::MatrixXd& predicted,
                                            const std::vector<ResidualBands::Band>& bands, double T, std::vector<double>& record) {
  const std::size_t N = static_cast<std::size_t>(measured.rows());
  const Eigen::Index J = measured.cols();
  std::vector<std::vector<double>> power(bands.size(), std::vector<double>(static_cast<std::size_t>(J), 0.0));
  record.assign(static_cast<std::size_t>(J), 0.0);
  Eigen::FFT<double> fft;
  std::vector<double> x(N);
  std::vector<std::complex<double>> X;
  const double n2 = static_cast<double>(N) * static_cast<double>(N);
  for (Eigen::Index j = 0; j < J; ++j) {
    for (std::size_t k = 0; k < N; ++k) {
      const auto i = static_cast<Eigen::Index>(k);
      x[k] = predicted(i, j) - measured(i, j);
      record[static_cast<std::size_t>(j)] += measured(i, j) * measured(i, j) / static_cast<double>(N);
    }
    fft.fwd(X, x);
    std::size_t band = 0;
    for (std::size_t b = 0; b <= N / 2; ++b) {
      const double f = static_cast<double>(b) / T;
      while (band + 1 < bands.size() && f >= bands[band + 1].from_hz) ++band;
      const double weight = (b == 0 || 2 * b == N) ? 1.0 : 2.0;
      power[band][static_cast<std::size_t>(j)] += weight * std::norm(X[b]) / n2;
    }
  }
  return power;
}

// The summary: the bands holding a tenth or more, largest first (at most three).
std::string summary_of(const ResidualBands& out, bool explained) {
  std::vector<const ResidualBands::Band*> big;
  for (const auto& b : out.bands)
    if (b.share >= 0.1) big.push_back(&b);
  std::sort(big.begin(), big.end(), [](const auto* a, const auto* b) { return a->share > b->share; });
  if (big.size() > 3) big.resize(3);
  std::string s;
  for (const auto* b : big)
    s += (s.empty() ? "" : ", ") + percent(b->share) + (b->mode > 0 ? " at " : " ") + b->holds + " (" + hz(b->from_hz) + "-" +
         hz(b->to_hz) + " Hz)";
  if (s.empty()) s = "spread over every band (none holds a tenth)";
  return "the residual's power: " + s + "; " + percent(out.at_modes) + " at the modes" +
         (explained ? std::string()
          : out.at_modes >= 0.5
              ? " (the model's modes miss the record's there: frequency, damping or shape)"
              : " (most lies where no mode of the model is: content the model does not carry — folded "
                "images of modes above Nyquist, an input misread between samples, noise)");
}

}  // namespace

ResidualBands residual_bands(const std::vector<double>& t, const Eigen::MatrixXd& measured, const Eigen::MatrixXd& predicted,
                             const std::vector<ModalEstimate>& modes, bool explained) {
  ResidualBands out;
  const std::size_t N = t.size();
  if (N < 8 || measured.rows() != static_cast<Eigen::Index>(N) || predicted.rows() != measured.rows() ||
      predicted.cols() != measured.cols() || measured.cols() == 0) {
    out.note = "no residual to split (fewer than 8 samples, or no model outputs)";
    return out;
  }
  if (!predicted.allFinite()) {
    out.note = "the model's outputs at the estimate are not finite";
    return out;
  }
  const double dt = (t.back() - t.front()) / static_cast<double>(N - 1);
  for (std::size_t k = 1; k < N; ++k)
    if (!(std::abs((t[k] - t[k - 1]) - dt) <= 1e-6 * dt)) {
      out.note = "the record is not uniformly sampled";
      return out;
    }
  const double T = static_cast<double>(N) * dt, nyquist = 0.5 / dt;
  std::vector<ResidualBands::Band> bands = band_edges(modes, T, nyquist);
  const Eigen::Index J = measured.cols();
  std::vector<double> record;  // each column's mean square
  const std::vector<std::vector<double>> power = band_power(measured, predicted, bands, T, record);
  double total = 0.0;
  for (std::size_t b = 0; b < bands.size(); ++b) {
    for (Eigen::Index j = 0; j < J; ++j) {
      const auto jj = static_cast<std::size_t>(j);
      bands[b].rms.push_back(std::sqrt(power[b][jj]));
      if (record[jj] > 0) bands[b].share += power[b][jj] / record[jj];
    }
    total += bands[b].share;
  }
  if (!(total > 0)) {
    out.note = "the residual is zero";
    out.bands = std::move(bands);
    for (auto& b : out.bands) b.share = 0.0;
    return out;
  }
  for (auto& b : bands) {
    b.share /= total;
    if (b.mode > 0) out.at_modes += b.share;
  }
  out.bands = std::move(bands);
  out.summary = summary_of(out, explained);
  return out;
}

}  // namespace scoleid::identify
