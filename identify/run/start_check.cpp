#include "scoleid/identify/run/start_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include <unsupported/Eigen/FFT>

#include "scoleid/identify/inverse/spectral_start.h"

namespace scoleid::identify {

namespace {

std::string num(double v, const char* fmt = "%.3g") {
  char b[48];
  std::snprintf(b, sizeof b, fmt, v);
  return b;
}

// The input's spectrum and the bins it carries (start_frf).
struct InputSpectrum {
  std::string input;
  const std::vector<std::complex<double>>& F;
  const std::vector<std::size_t>& bins;
  double fmax, T;
};

// One sensor's H1 against the input, its lines at the peaks, and the medians.
StartFrf sensor_frf(const Problem& p, const MatrixXd& y, Eigen::Index j, const InputSpectrum& in, const std::vector<SpectralPeak>& peaks) {
  const auto& z = p.data.z;
  const std::size_t N = p.data.t.size();
  const auto& F = in.F;
  const auto& bins = in.bins;
  const double fmax = in.fmax, T = in.T;
  Eigen::FFT<double> fft;
  std::vector<double> x(N);
  std::vector<std::complex<double>> Z, Y;
  const std::string& input = in.input;
  StartFrf r;
  r.input = input;
  r.sensor = p.scenario.sensors[static_cast<std::size_t>(j)].name;
  for (std::size_t k = 0; k < N; ++k) x[k] = z(static_cast<Eigen::Index>(k), j);
  fft.fwd(Z, x);
  for (std::size_t k = 0; k < N; ++k) x[k] = y(static_cast<Eigen::Index>(k), j);
  fft.fwd(Y, x);
  for (std::size_t b : bins) {
    r.f.push_back(static_cast<double>(b) / T);
    r.measured.push_back(Z[b] / F[b]);
    r.model.push_back(Y[b] / F[b]);
  }
  for (const auto& pk : peaks) {
    const auto at = std::lower_bound(r.f.begin(), r.f.end(), pk.f);
    if (at == r.f.end() || (at == r.f.begin() && *at > pk.f * 1.001)) continue;
    std::size_t b = static_cast<std::size_t>(at - r.f.begin());
    if (b > 0 && std::abs(r.f[b - 1] - pk.f) < std::abs(r.f[b] - pk.f)) --b;
    if (std::abs(r.f[b] - pk.f) > 1.5 / T) continue;  // the peak's bin is not among those the input carries
    StartFrf::Line l;
    l.hz = r.f[b];
    l.measured = std::abs(r.measured[b]);
    l.model = std::abs(r.model[b]);
    l.ratio = l.model > 0 ? l.measured / l.model : NAN;
    l.phase_deg = l.model > 0 && l.measured > 0 ? std::arg(r.measured[b] / r.model[b]) * 180.0 / M_PI : NAN;
    r.lines.push_back(l);
  }
  std::sort(r.lines.begin(), r.lines.end(), [](const auto& a, const auto& b) { return a.hz < b.hz; });
  // The medians over the bins where the input carries at least a tenth of its largest amplitude
  // (below that, a chirp's or a tap's leakage: the ratio of two small numbers).
  std::vector<double> ratios, phases;
  for (std::size_t b = 0; b < r.f.size(); ++b)
    if (std::abs(F[bins[b]]) >= 0.1 * fmax && std::abs(r.model[b]) > 0 && std::abs(r.measured[b]) > 0) {
      ratios.push_back(std::abs(r.measured[b]) / std::abs(r.model[b]));
      phases.push_back(std::abs(std::arg(r.measured[b] / r.model[b])) * 180.0 / M_PI);
    }
  auto median = [](std::vector<double> v) {
    if (v.empty()) return std::nan("");
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  r.median_ratio = median(ratios);
  r.median_phase_deg = median(phases);
  return r;
}

// H1 of each sensor against the one data input (StartFrf), at the record's peaks `peaks`.
void start_frf(const Problem& p, const MatrixXd& y, const std::vector<SpectralPeak>& peaks, StartCheck& out) {
  const auto& t = p.data.t;
  const auto& z = p.data.z;
  if (p.columns.inputs_from_data.size() != 1) {
    out.frf_note = p.columns.inputs_from_data.empty() ? "no input is read from the data"
                                                      : "several inputs are read from the data (a single-input estimate would be biased)";
    return;
  }
  const std::string input = p.columns.inputs_from_data.front();
  std::size_t i = 0;
  while (i < p.scenario.inputs.size() && p.scenario.inputs[i].name != input) ++i;
  if (i >= p.signals.size()) return;
  const std::size_t N = t.size();
  const double dt = (t.back() - t.front()) / static_cast<double>(N - 1);
  for (std::size_t k = 1; k < N; ++k)
    if (!(std::abs(t[k] - t[k - 1] - dt) <= 1e-6 * dt)) {
      out.frf_note = "the record is not uniformly sampled";
      return;
    }
  Eigen::FFT<double> fft;
  std::vector<double> x(N);
  std::vector<std::complex<double>> F;
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t k = 0; k < N; ++k) {
    x[k] = p.signals[i](t[k]);
    lo = std::min(lo, x[k]);
    hi = std::max(hi, x[k]);
  }
  // A constant input (to its rounding) carries nothing at any frequency but zero: its bins are
  // rounding, and a ratio to them is none.
  if (!(hi - lo > 1e-9 * std::max(std::abs(lo), std::abs(hi)))) {
    out.frf_note = "input '" + input + "' is constant: it carries nothing in the band";
    return;
  }
  fft.fwd(F, x);
  const double T = static_cast<double>(N) * dt;
  const auto& band = p.scenario.identification.band;
  double fmax = 0.0;
  for (std::size_t b = 1; b <= N / 2; ++b) fmax = std::max(fmax, std::abs(F[b]));
  std::vector<std::size_t> bins;
  for (std::size_t b = 1; b <= N / 2; ++b) {
    const double f = static_cast<double>(b) / T;
    if (band.size() == 2 && (f < band[0] || f > band[1])) continue;
    if (std::abs(F[b]) >= 1e-3 * fmax && fmax > 0) bins.push_back(b);
  }
  if (bins.empty()) {
    out.frf_note = "input '" + input + "' carries nothing in the band";
    return;
  }
  for (Eigen::Index j = 0; j < z.cols(); ++j)
    out.frf.push_back(sensor_frf(p, y, j, {input, F, bins, fmax, T}, peaks));
}

// How the sensors read the model at the start (check_start's tallies).
struct Tally {
  int inverted, scaled, assessed;
  double a_lo, a_hi;  // the smallest and largest |scale| of a correlated sensor
};

// The warnings: one for the input where every sensor agrees, else one per sensor.
void add_warnings(const Problem& p, const std::string& set_aside, const Tally& c, StartCheck& out) {
  const int inverted = c.inverted, scaled = c.scaled, assessed = c.assessed;
  const double a_lo = c.a_lo, a_hi = c.a_hi;
  // The one input read from the data, if there is exactly one: where every sensor agrees, it is the suspect.
  const std::string input = p.columns.inputs_from_data.size() == 1 ? p.columns.inputs_from_data.front() : std::string();
  const std::string span = "over " + num(out.from, "%.4g") + " .. " + num(out.to, "%.4g") + " s at the start" +
                           (set_aside.empty() ? "" : ", the static offset of input " + set_aside + " set aside");
  const std::string window = " (" + span + ")";
  if (assessed > 1 && inverted == assessed && !input.empty()) {
    out.warnings.push_back("every sensor reads the model's response inverted" + window + ": input '" + input +
                           "' is likely of the other sign (a load cell mounted or wired the other way round); "
                           "conditioning: {sign: -1} on it states that");
  } else {
    for (const auto& s : out.sensors)
      if (std::isfinite(s.correlation) && s.correlation < -0.5)
        out.warnings.push_back("sensor '" + s.name + "' reads the model's response inverted (correlation " + num(s.correlation, "%.2f") + " " +
                               span + "): mounted or wired the other way round? conditioning: {sign: -1} on it states that");
  }
  if (assessed > 1 && scaled == assessed && !input.empty() && a_hi <= 2.0 * a_lo) {
    out.warnings.push_back("every sensor reads about " + num(std::sqrt(a_lo * a_hi)) + " times the model's response" + window +
                           ": input '" + input + "' is likely in another unit or calibration (state its column's unit, or "
                           "conditioning: {scale: ...} on it)");
  } else {
    for (const auto& s : out.sensors)
      if (std::isfinite(s.correlation) && std::abs(s.correlation) >= 0.5 && (std::abs(s.scale) > 3.0 || std::abs(s.scale) < 1.0 / 3.0))
        out.warnings.push_back("sensor '" + s.name + "' reads " + num(std::abs(s.scale)) + " times the model's response" + window +
                               ": another unit or calibration than stated? (its column's unit, or conditioning: {scale: ...})");
  }
}

}  // namespace

StartCheck check_start(const Problem& p, Objective& obj, const VectorXd& q) {
  StartCheck out;
  const auto& t = p.data.t;
  const auto& z = p.data.z;
  if (t.size() < 4 || z.cols() == 0) return out;
  // An input read with a static offset (problem.cpp input_offsets) drives the model with a constant
  // force from the first sample, whose ringing no record shows: the model is run without it (the
  // column less its mean; the model is linear), so the signs and scales are still judged.
  std::unique_ptr<Objective> unoffset;
  std::string set_aside;
  if (!p.static_offsets.empty()) {
    std::vector<io::Signal> signals = p.signals;
    for (const auto& [i, mean] : p.static_offsets) {
      auto terms = signals[i].terms();
      for (auto& term : terms)
        if (term.type == io::SignalTerm::Type::Table || term.type == io::SignalTerm::Type::CubicTable)
          for (double& v : term.values) v -= mean;
      signals[i] = io::Signal(std::move(terms));
      set_aside += std::string(set_aside.empty() ? "" : ", ") + "'" + p.scenario.inputs[i].name + "'";
    }
    unoffset = std::make_unique<Objective>(p.model(), *p.params, std::move(signals), p.data, p.objective_options);
  }
  Objective& model = unoffset ? *unoffset : obj;
  obj.set_horizon(obj.data_end());
  model.set_horizon(model.data_end());
  const MatrixXd y = model.predict(q);
  // The window: ten cycles of the record's lowest peak from where the inputs begin to act.
  out.from = model.response_start();
  out.to = t.back();
  auto peaks = spectral_peaks(t, z);
  if (!peaks.empty()) {
    double f_low = peaks.front().f;
    for (const auto& pk : peaks) f_low = std::min(f_low, pk.f);
    out.to = std::min(t.back(), out.from + 10.0 / f_low);
  }
  start_frf(p, y, peaks, out);
  const auto first = static_cast<Eigen::Index>(std::lower_bound(t.begin(), t.end(), out.from) - t.begin());
  const auto last = static_cast<Eigen::Index>(std::upper_bound(t.begin(), t.end(), out.to) - t.begin());
  const Eigen::Index n = last - first;
  if (n < 4) return out;
  int inverted = 0, scaled = 0, assessed = 0;
  double a_lo = INFINITY, a_hi = 0.0;
  for (Eigen::Index k = 0; k < z.cols(); ++k) {
    StartCheck::Sensor s;
    s.name = p.scenario.sensors[static_cast<std::size_t>(k)].name;
    const auto ym = y.col(k).segment(first, n), zm = z.col(k).segment(first, n);
    const double yy = ym.squaredNorm(), zz = zm.squaredNorm(), yz = ym.dot(zm);
    s.correlation = yy > 0 && zz > 0 ? yz / std::sqrt(yy * zz) : NAN;
    s.scale = yy > 0 ? yz / yy : NAN;
    out.sensors.push_back(s);
    if (!std::isfinite(s.correlation)) continue;
    ++assessed;
    if (s.correlation < -0.5) ++inverted;
    if (std::abs(s.correlation) >= 0.5) {
      const double a = std::abs(s.scale);
      a_lo = std::min(a_lo, a);
      a_hi = std::max(a_hi, a);
      if (a > 3.0 || a < 1.0 / 3.0) ++scaled;
    }
  }
  add_warnings(p, set_aside, {inverted, scaled, assessed, a_lo, a_hi}, out);
  return out;
}

}  // namespace scoleid::identify
