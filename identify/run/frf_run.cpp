// An identification in the frequency domain (frf_run.h; docs/theory.md §6.10).
#include "scoleid/identify/run/frf_run.h"

#include <stdexcept>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>

#include "scoleid/identify/inverse/modal_misfit.h"
#include "scoleid/identify/run/assessment.h"
#include "scoleid/identify/run/strategy.h"
#include "scoleid/io/error.h"
#include "scoleid/io/frf_estimate.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/progress.h"

namespace scoleid::identify {

namespace {

using io::fail_field;
constexpr double kTwoPi = 6.283185307179586476925286766559;

double effective_averages(int segments, io::FrfWindowKind window, double overlap) {
  return io::welch_effective_averages(segments, window == io::FrfWindowKind::Hann ? io::FrfWindow::Hann : io::FrfWindow::Rectangular,
                                      overlap);
}

// The one input the FRFs are per unit of: the scenario's only input.
int frf_input_index(const Problem& p) {
  const auto& sc = p.scenario;
  if (sc.inputs.size() != 1) throw std::logic_error("frf_input_index: " + std::to_string(sc.inputs.size()) + " inputs (identify::check_scenario refuses it)");
  return 0;
}

// The record's sample rate, refusing a record that is not uniformly sampled.
double uniform_rate(const Problem& p) {
  const auto& t = p.data.t;
  if (t.size() < 16) throw io::InputError(p.data_source + ": " + std::to_string(t.size()) + " samples are too few for frequency responses");
  const double dt = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  for (std::size_t i = 1; i < t.size(); ++i)
    if (std::abs(t[i] - t[i - 1] - dt) > 1e-6 * dt)
      throw io::InputError(p.data_source + ": frequency responses need uniformly sampled data: the interval at t = " +
                           io::format_value(t[i - 1]) + " is " + io::format_value(t[i] - t[i - 1]) + " s against the mean " +
                           io::format_value(dt) + " s (state data.sample_rate if the clock is uniform)");
  return 1.0 / dt;
}

// Lines outside identification.band, when stated, dropped (a data set with none left refused).
void keep_band(const Problem& p, io::FrfData& d) {
  const auto& band = p.scenario.identification.band;
  if (band.empty()) return;
  io::FrfData out = d;
  out.f_hz.clear();
  for (auto& ch : out.channels) ch.H.clear(), ch.variance.clear(), ch.coherence.clear();
  for (std::size_t k = 0; k < d.f_hz.size(); ++k) {
    if (d.f_hz[k] < band[0] || d.f_hz[k] > band[1]) continue;
    out.f_hz.push_back(d.f_hz[k]);
    for (std::size_t s = 0; s < d.channels.size(); ++s) {
      out.channels[s].H.push_back(d.channels[s].H[k]);
      out.channels[s].variance.push_back(d.channels[s].variance[k]);
      if (!d.channels[s].coherence.empty()) out.channels[s].coherence.push_back(d.channels[s].coherence[k]);
    }
  }
  if (out.f_hz.empty())
    fail_field(p.scenario.source, "identification.band", "keeps none of the data's " + std::to_string(d.f_hz.size()) + " lines (" +
                                                             io::format_value(d.f_hz.front()) + " to " + io::format_value(d.f_hz.back()) + " Hz)",
               "[" + io::format_value(band[0]) + ", " + io::format_value(band[1]) + "]");
  d = std::move(out);
}

// Checks shared by both sources, and the variance's F-law scaling (frf_run.h).
void finish_frf(Problem& p, io::FrfData d, double dof) {
  const auto& sc = p.scenario;
  if (!sc.identification.uncertain.empty()) throw std::logic_error("finish_frf: declared uncertainties (identify::check_scenario refuses them)");
  keep_band(p, d);
  if (dof > 0.0 && !(dof > 4.0))
    fail_field(sc.source, "identification.frf.segment",
               "leaves too few averages to weigh the lines (their variances rest on " + io::format_value(dof) +
                   " degrees of freedom; at least 5 segments are needed): shorten the segment",
               io::format_value(sc.identification.frf.segment));
  const double scale = dof > 0.0 ? dof / (dof - 2.0) : 1.0;
  for (auto& ch : d.channels)
    for (std::size_t k = 0; k < ch.variance.size(); ++k) {
      const double v = ch.variance[k] * scale;
      if (!(v > 0.0) || !std::isfinite(v) || !std::isfinite(ch.H[k].real()) || !std::isfinite(ch.H[k].imag()))
        throw io::InputError(d.source + ": sensor '" + ch.sensor + "' at " + io::format_value(d.f_hz[k]) +
                             " Hz has no usable value (H " + io::format_value(ch.H[k].real()) + "+" + io::format_value(ch.H[k].imag()) +
                             "i, variance " + io::format_value(v) + "): a line without input or without noise cannot be weighted");
      ch.variance[k] = v;
    }
  p.frf_input = frf_input_index(p);
  p.frf_sensors.clear();
  for (const auto& ch : d.channels) {
    int found = -1;
    for (std::size_t j = 0; j < p.model().sensors.size(); ++j)
      if (p.model().sensors[j].name == ch.sensor) found = static_cast<int>(j);
    if (found < 0) throw std::logic_error("frf: channel '" + ch.sensor + "' is no model sensor");
    p.frf_sensors.push_back(found);
  }
  p.frf_variance_dof = dof;
  p.frf = std::move(d);
}

// The impact window's automatic decay a (docs/theory.md §6.10). The window cuts the record at T
// while it may still ring: a response ringing at RMS A over the record's last 5 % (what the tail
// holds beyond its noise σ, its mean and trend removed: A² = max(0, ms − σ²)) leaves e^{−aT} A
// there, and that free ringing, cut off, reaches a line near its mode as about e^{−aT} A fs/(√2 a)
// (a cosine of amplitude √2 A summed under e^{−a t}), against the line's noise σ (Σ w²)^½ ≈
// σ (fs/2a)^½. The smallest a >= ln 100 / T that puts the first at a tenth of the second for
// every sensor:
//   a T >= ln(10 A/σ) + ½ ln(fs/a),
// at most ln 1e12 / T (by bisection; the left side grows with a, the right falls). A channel whose
// tail is not finite counts as ringing at the cap.
double impact_decay(const std::vector<const double*>& y, std::size_t n, double fs, const std::vector<double>& sigma) {
  const double T = static_cast<double>(n) / fs;
  const std::size_t tail = std::min(n, std::max<std::size_t>(16, n / 20));
  double ratio = 0.0;  // the largest A/σ
  for (std::size_t s = 0; s < y.size(); ++s) {
    // Least-squares line through the tail (k = 0 .. m−1 centred), then the mean square about it.
    const double m = static_cast<double>(tail), kc = 0.5 * (m - 1.0);
    double sy = 0.0, sky = 0.0, skk = 0.0;
    for (std::size_t i = 0; i < tail; ++i) {
      const double k = static_cast<double>(i) - kc, v = y[s][n - tail + i];
      sy += v, sky += k * v, skk += k * k;
    }
    const double mean = sy / m, slope = skk > 0 ? sky / skk : 0.0;
    double ss = 0.0;
    for (std::size_t i = 0; i < tail; ++i) {
      const double r = y[s][n - tail + i] - mean - slope * (static_cast<double>(i) - kc);
      ss += r * r;
    }
    const double ringing = std::sqrt(std::max(0.0, ss / m - sigma[s] * sigma[s])) / sigma[s];
    ratio = std::isfinite(ringing) ? std::max(ratio, ringing) : INFINITY;
  }
  const auto enough = [&](double a) { return a * T >= std::log(10.0 * ratio) + 0.5 * std::log(fs / a); };
  double lo = std::log(100.0) / T, hi = std::log(1e12) / T;
  if (!(ratio > 0) || enough(lo)) return lo;
  if (!enough(hi)) return hi;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (enough(mid) ? hi : lo) = mid;
  }
  return hi;
}

}  // namespace

void frf_from_record(Problem& p) {
  const auto& sc = p.scenario;
  const auto& spec = sc.identification.frf;
  const int input = frf_input_index(p);
  const double fs = uniform_rate(p);
  const std::size_t n = p.data.t.size();
  // The input and responses of samples [b, e) as arrays (the whole record for the lines' fit, chunks
  // for Welch, which streams).
  std::vector<double> x;
  std::vector<std::vector<double>> y(static_cast<std::size_t>(p.data.sensors()));
  std::vector<const double*> yp(y.size());
  const auto take = [&](std::size_t b, std::size_t e) {
    x.resize(e - b);
    for (std::size_t i = b; i < e; ++i) x[i - b] = p.signals[static_cast<std::size_t>(input)](p.data.t[i]);
    for (std::size_t s = 0; s < y.size(); ++s) {
      y[s].resize(e - b);
      for (std::size_t i = b; i < e; ++i) y[s][i - b] = p.data.z(static_cast<Eigen::Index>(i), static_cast<int>(s));
      yp[s] = y[s].data();
    }
  };
  bool only_lines = false;
  const std::vector<double> signal_lines = sc.inputs[static_cast<std::size_t>(input)].signal.lines(&only_lines);
  io::FrfEstimatorKind kind = spec.estimator;
  if (kind == io::FrfEstimatorKind::Auto) kind = (!spec.lines.empty() || only_lines) ? io::FrfEstimatorKind::Lines : io::FrfEstimatorKind::H1;
  const std::string& name = sc.inputs[static_cast<std::size_t>(input)].name;
  if (kind == io::FrfEstimatorKind::Lines) {
    io::LinesOptions o;
    o.sample_rate = fs;
    o.lines_hz = spec.lines.empty() ? signal_lines : spec.lines;
    if (o.lines_hz.empty())
      fail_field(sc.source, "identification.frf.lines",
                 "must list the input's frequencies for the lines estimator (the input's signal has no sine or multisine term)", "[]");
    for (double f : o.lines_hz)
      if (!(f < 0.5 * fs))
        fail_field(sc.source, "identification.frf.lines", "must lie below the record's Nyquist frequency " + io::format_value(0.5 * fs) + " Hz",
                   io::format_value(f));
    io::FrfData d;
    take(0, n);
    try {
      d = io::harmonic_frf(x.data(), yp, n, o, p.data_source, name, p.data.names);
    } catch (const std::invalid_argument& e) {
      throw io::InputError(p.data_source + ": identification.frf (lines): " + e.what());
    }
    p.frf_note = std::to_string(d.lines()) + " lines of input '" + name + "' fitted harmonically over " + io::format_value(p.data.t.back() - p.data.t.front()) + " s";
    finish_frf(p, std::move(d), 0.0);
    return;
  }
  if (kind == io::FrfEstimatorKind::Impact) {
    // One segment of the whole record under an exponential window on force and responses: the FRF
    // at s = a + iω, weighted by the sensors' noise levels (io/frf_estimate.h impact_frf).
    io::ImpactOptions o;
    o.sample_rate = fs;
    const double T = static_cast<double>(n) / fs;
    o.f_max = 0.8 * 0.5 * fs;
    for (int s = 0; s < p.data.sensors(); ++s) {
      const double sd = p.noise_std[static_cast<std::size_t>(s)];
      if (!(sd > 0))
        fail_field(sc.source, "sensors." + p.data.names[static_cast<std::size_t>(s)] + ".noise_std",
                   "must be stated (or found in the record's quiet start) for identification.frf.estimator impact: one hit's "
                   "FRF has no scatter of its own to weigh it by",
                   io::format_value(sd));
      o.response_std.push_back(sd);
    }
    take(0, n);
    o.decay = spec.decay >= 0 ? spec.decay : impact_decay(yp, n, fs, o.response_std);
    io::FrfData d;
    try {
      d = io::impact_frf(x.data(), yp, n, o, p.data_source, name, p.data.names);
    } catch (const std::invalid_argument& e) {
      throw io::InputError(p.data_source + ": identification.frf (impact): " + e.what());
    }
    char note[240];
    std::snprintf(note, sizeof note,
                  "impact FRFs of input '%s': one segment of %.4g s under e^{-%.4g t} (%.3g at its end), lines every %.4g Hz up to %.4g Hz, "
                  "compared with the model at s = %.4g + i omega",
                  name.c_str(), T, o.decay, std::exp(-o.decay * T), fs / static_cast<double>(n), d.f_hz.back(), o.decay);
    p.frf_note = note;
    finish_frf(p, std::move(d), 0.0);
    return;
  }
  io::WelchOptions o;
  o.sample_rate = fs;
  o.overlap = spec.overlap;
  o.window = spec.window == io::FrfWindowKind::Hann ? io::FrfWindow::Hann : io::FrfWindow::Rectangular;
  o.estimator = kind == io::FrfEstimatorKind::H2 ? io::FrfEstimator::H2 : io::FrfEstimator::H1;
  // Eight segments of a power of two samples by default.
  long seg = spec.segment > 0 ? std::lround(spec.segment * fs) : 1L << static_cast<int>(std::floor(std::log2(std::max(2.0, n / 4.5))));
  if (seg < 16 || seg > static_cast<long>(n))
    fail_field(sc.source, "identification.frf.segment", "must hold between 16 samples and the record (" + std::to_string(n) + " samples)",
               io::format_value(spec.segment));
  o.segment = seg;
  o.f_max = 0.8 * 0.5 * fs;
  io::WelchFrf w(p.data.sensors(), o);
  for (std::size_t b = 0; b < n; b += std::size_t{1} << 16) {
    const std::size_t e = std::min(n, b + (std::size_t{1} << 16));
    take(b, e);
    w.add(x.data(), yp, e - b);
  }
  io::FrfData d;
  try {
    d = w.result(p.data_source, name, p.data.names);
  } catch (const std::invalid_argument& e) {
    throw io::InputError(p.data_source + ": identification.frf: " + e.what());
  }
  const double dof = 2.0 * (effective_averages(w.segments(), spec.window, spec.overlap) - 1.0);
  char note[200];
  std::snprintf(note, sizeof note, "Welch %s of input '%s': %d segments of %.4g s (%s, overlap %.2g), lines every %.4g Hz up to %.4g Hz",
                kind == io::FrfEstimatorKind::H2 ? "H2" : "H1", name.c_str(), w.segments(), seg / fs, to_string(spec.window),
                spec.overlap, fs / seg, o.f_max);
  p.frf_note = note;
  finish_frf(p, std::move(d), dof);
}

void frf_from_file(Problem& p, io::FrfData d, const std::vector<int>& orders) {
  for (std::size_t s = 0; s < d.channels.size(); ++s) {
    auto& ch = d.channels[s];
    const auto it = std::find_if(p.model().sensors.begin(), p.model().sensors.end(), [&](const ModelSensor& m) { return m.name == ch.sensor; });
    if (it == p.model().sensors.end())
      fail_field(p.scenario.source, "identification.frf.stations", "names a sensor the scenario does not have", "'" + ch.sensor + "'");
    // Receptance, mobility, accelerance: H_sensor = (iω)^(o_sensor − o_file) H_file.
    const int shift = it->order - (s < orders.size() ? orders[s] : it->order);
    for (std::size_t k = 0; k < ch.H.size(); ++k) {
      std::complex<double> f = std::pow(std::complex<double>(0.0, kTwoPi * d.f_hz[k]), shift);
      ch.H[k] *= f;
      ch.variance[k] *= std::norm(f);
    }
  }
  p.frf_note = std::to_string(d.lines()) + " lines of " + std::to_string(d.channels.size()) + " FRFs read from " + d.source;
  finish_frf(p, std::move(d), 0.0);
}

FitTest frf_fit_test(const Problem& p, FrfMisfit& m, const VectorXd& q) {
  FitTest f;
  const io::FrfData& d = m.data();
  const int L = d.lines(), S = static_cast<int>(d.channels.size());
  const double m_err = model_error(p);
  f.model_error = m_err;
  if (!q.allFinite()) {
    f.message = "not tested: the estimate is not finite";
    return f;
  }
  m.set_horizon(m.data_end());
  const ComplexMatrix H = m.predict(q);
  // The discretisation estimate: the same model on twice the elements.
  ComplexMatrix D = ComplexMatrix::Zero(L, S);
  bool have_d = false;
  try {
    const auto fine = make_structure(p.scenario, 2 * p.structure->elements());
    const auto params = fine->parameterize(p.scenario);
    if (params->names() == p.params->names()) {
      FrfMisfit fm(fine->model(), *params, d, m.sensors(), m.input());
      D = fm.predict(q) - H;
      have_d = D.allFinite();
      if (!have_d) D.setZero();
    }
  } catch (const io::Interrupted&) {
    throw;
  } catch (const std::domain_error&) {
    // A refined model that cannot be solved at q: no discretisation estimate.
  }
  const double kappa = p.frf_variance_dof > 0.0 ? p.frf_variance_dof / (p.frf_variance_dof - 4.0) : 1.0;
  double excess = 0.0, allowed_d = 0.0, allowed_m_unit = 0.0;
  for (int s = 0; s < S; ++s) {
    const auto& ch = d.channels[static_cast<std::size_t>(s)];
    SensorFit sf;
    sf.name = ch.sensor;
    sf.noise_origin = d.estimator == "file" ? "file" : d.estimator == "lines" ? "harmonic fit" : "segments' scatter";
    double chi2 = 0.0, sig = 0.0, res = 0.0, var = 0.0, dd = 0.0, a_d = 0.0, a_m = 0.0;
    for (int k = 0; k < L; ++k) {
      const double v = ch.variance[static_cast<std::size_t>(k)];
      const std::complex<double> delta = H(k, s) - ch.H[static_cast<std::size_t>(k)];
      chi2 += 2.0 * std::norm(delta) / v;
      sig += std::norm(ch.H[static_cast<std::size_t>(k)]);
      res += std::norm(delta);
      var += v;
      dd += std::norm(D(k, s));
      a_d += 8.0 * std::norm(D(k, s)) / v;
      a_m += 2.0 * std::norm(ch.H[static_cast<std::size_t>(k)]) / v;
    }
    sf.rms_signal = std::sqrt(sig / L);
    sf.rms_residual = std::sqrt(res / L);
    sf.noise = std::sqrt(var / L);
    sf.systematic = std::sqrt(std::max(0.0, res - var) / L);
    sf.discretisation = have_d ? std::sqrt(dd / L) : std::nan("");
    sf.allowed = std::sqrt((4.0 * dd + m_err * m_err * sig) / L);
    const double n_s = 2.0 * L;
    sf.explained = chi2 - n_s <= a_d + m_err * m_err * a_m + 3.0 * std::sqrt(2.0 * n_s * kappa);
    excess += chi2 - n_s;
    allowed_d += a_d;
    allowed_m_unit += a_m;
    f.sensors.push_back(sf);
  }
  const double N = 2.0 * L * S, band = 3.0 * std::sqrt(2.0 * N * kappa);
  f.explains_data = excess <= allowed_d + m_err * m_err * allowed_m_unit + band;
  f.within_noise_and_discretisation = excess <= allowed_d + band;
  f.ratio = std::sqrt(std::max(0.0, excess) / (allowed_d + m_err * m_err * allowed_m_unit + band));
  f.model_error_needed = allowed_m_unit > 0 ? std::sqrt(std::max(0.0, excess - allowed_d - band) / allowed_m_unit) : 0.0;
  char msg[400];
  if (f.explains_data && !f.within_noise_and_discretisation)
    std::snprintf(msg, sizeof msg,
                  "passes only with the model-error allowance of %.3g %% (identification.model_error): the residual needs at least %.3g %%, "
                  "beyond what noise and discretisation allow (weighted chi2 %.6g over %.0f values)",
                  100.0 * m_err, 100.0 * f.model_error_needed, excess + N, N);
  else
    std::snprintf(msg, sizeof msg, "%s: weighted chi2 %.6g over %.0f values (noise band %.3g, discretisation %.3g, model error %.3g)%s",
                  f.explains_data ? "explains the data" : "does not explain the data", excess + N, N, band, allowed_d,
                  m_err * m_err * allowed_m_unit,
                  f.explains_data || f.model_error_needed <= 0 ? "" : (", needs a model error of at least " + io::format_value(100.0 * f.model_error_needed) + " %").c_str());
  f.message = msg;
  return f;
}

namespace {
// The iteration table on stderr (io::progress): iteration, parameters, cost, the continuation's top line.
void print_iteration(const Problem& p, const IterationRecord& r) {
  const int P = p.params->size();
  if (r.k == 0) {
    io::progress("%5s", "iter");
    for (int i = 0; i < P; ++i) io::progress(" %13s", p.params->names()[static_cast<std::size_t>(i)].c_str());
    io::progress(" %13s %10s\n", "cost", "up to [Hz]");
  }
  io::progress("%5d", r.k);
  for (int i = 0; i < P; ++i) io::progress(" %13.6g", r.q[i]);
  io::progress(" %13.6e %10.4g\n", r.cost, r.horizon);
}

// Fisher information of the weighted residuals (all lines) at q.
FisherInformation frf_fisher(FrfMisfit& m, const VectorXd& q) {
  m.set_horizon(m.data_end());
  VectorXd r;
  MatrixXd J;
  m.residuals(q, r, &J);
  FisherInformation fi;
  fi.F = J.transpose() * J;
  fi.chi2 = r.squaredNorm();
  fi.data_values = static_cast<long>(r.size());
  const double N = static_cast<double>(r.size());
  fi.systematic = std::max(0.0, fi.chi2 - (N + 2.0 * std::sqrt(2.0 * N)));
  for (const auto& ch : m.data().channels) {
    double v = 0.0;
    for (double x : ch.variance) v += x;
    fi.noise_std.push_back(std::sqrt(v / static_cast<double>(ch.variance.size())));
  }
  fi.stated_noise = true;
  return fi;
}
}  // namespace

namespace {
// The measured FRFs' resonance peaks: local maxima of P_k = Σ_s |Ĥ_ks|² / Σ_k' |Ĥ_k's|² that are the
// largest within ±3 % of their frequency (at least ±2 lines), stand at least four times (6 dB)
// above the higher of the two lowest points between them and the next higher line on either side
// (their prominence: a resonance rises far above its skirts, a ripple does not), and are at least
// 10⁻³ of the strongest; at most eight, each refined by the parabola through log P at its line and
// its neighbours.
std::vector<double> frf_peaks(const io::FrfData& d) {
  const int L = d.lines();
  std::vector<double> P(static_cast<std::size_t>(L), 0.0);
  for (const auto& ch : d.channels) {
    double total = 0.0;
    for (const auto& h : ch.H) total += std::norm(h);
    if (total > 0)
      for (int k = 0; k < L; ++k) P[static_cast<std::size_t>(k)] += std::norm(ch.H[static_cast<std::size_t>(k)]) / total;
  }
  std::vector<std::pair<double, double>> peaks;  // power, Hz
  for (int k = 1; k + 1 < L; ++k) {
    const double f = d.f_hz[static_cast<std::size_t>(k)];
    if (!(P[static_cast<std::size_t>(k)] > P[static_cast<std::size_t>(k - 1)] && P[static_cast<std::size_t>(k)] >= P[static_cast<std::size_t>(k + 1)]))
      continue;
    bool largest = true;
    for (int i = 0; i < L && largest; ++i) {
      const double fi = d.f_hz[static_cast<std::size_t>(i)];
      const bool near = std::abs(fi - f) <= 0.03 * f || std::abs(i - k) <= 2;
      if (i != k && near && P[static_cast<std::size_t>(i)] > P[static_cast<std::size_t>(k)]) largest = false;
    }
    if (!largest) continue;
    double left = P[static_cast<std::size_t>(k)], right = left;
    for (int i = k - 1; i >= 0 && P[static_cast<std::size_t>(i)] <= P[static_cast<std::size_t>(k)]; --i) left = std::min(left, P[static_cast<std::size_t>(i)]);
    for (int i = k + 1; i < L && P[static_cast<std::size_t>(i)] <= P[static_cast<std::size_t>(k)]; ++i) right = std::min(right, P[static_cast<std::size_t>(i)]);
    if (!(P[static_cast<std::size_t>(k)] >= 4.0 * std::max(left, right))) continue;
    const double a = std::log(P[static_cast<std::size_t>(k - 1)]), b = std::log(P[static_cast<std::size_t>(k)]),
                 c = std::log(P[static_cast<std::size_t>(k + 1)]);
    const double f0 = d.f_hz[static_cast<std::size_t>(k - 1)], f2 = d.f_hz[static_cast<std::size_t>(k + 1)];
    double shift = a - 2 * b + c < 0 ? 0.5 * (a - c) / (a - 2 * b + c) : 0.0;  // in lines, for even spacing
    shift = std::clamp(shift, -0.5, 0.5);
    const double fk = shift < 0 ? f + shift * (f - f0) : f + shift * (f2 - f);
    peaks.emplace_back(P[static_cast<std::size_t>(k)], fk);
  }
  std::sort(peaks.rbegin(), peaks.rend());
  std::vector<double> out;
  for (const auto& [pw, f] : peaks)
    if (pw >= 1e-3 * peaks.front().first && out.size() < 8) out.push_back(f);
  std::sort(out.begin(), out.end());
  return out;
}

// The peaks' start (frf_run.h): the model's natural frequencies fitted to the measured peaks
// (inverse/modal_misfit.h, frequencies alone, each known to a line's spacing), from q0; q0 when that
// fit does not converge or has nothing to fit.
VectorXd peak_start(const Problem& p, const VectorXd& q0, std::string& note) {
  const io::FrfData& d = *p.frf;
  const auto peaks = frf_peaks(d);
  if (peaks.empty()) {
    note = "no resonance peak in the FRFs: the fit starts from the initial values";
    return q0;
  }
  io::ModalData md;
  md.source = "the FRFs' peaks";
  for (std::size_t i = 0; i < peaks.size(); ++i) {
    io::ModalData::Mode mode;
    mode.label = static_cast<int>(i + 1);
    mode.frequency_hz = peaks[i];
    const auto it = std::lower_bound(d.f_hz.begin(), d.f_hz.end(), peaks[i]);
    const double spacing = it != d.f_hz.end() && it != d.f_hz.begin() ? *it - *(it - 1) : 0.01 * peaks[i];
    mode.frequency_std_hz = std::max(spacing, 1e-3 * peaks[i]);
    md.modes.push_back(mode);
  }
  try {
    ModalMisfit modal(p.model(), *p.params, md);
    OptimizerOptions o;
    o.method = io::Method::GaussNewton;
    o.max_iterations = 30;
    const OptimizerSummary s = minimize(modal, q0, o);
    if (!s.converged() || !s.q.allFinite()) {
      note = "the model's modes could not be fitted to the FRFs' " + std::to_string(peaks.size()) + " peaks (" + s.message + "): the fit starts from the initial values";
      return q0;
    }
    char b[200];
    std::snprintf(b, sizeof b, "the model's modes fitted to the FRFs' %zu peaks (%.4g to %.4g Hz) in %d iterations", peaks.size(),
                  peaks.front(), peaks.back(), s.iterations_done);
    note = b;
    return s.q;
  } catch (const io::Interrupted&) {
    throw;
  } catch (const std::domain_error& e) {
    note = std::string("the peaks' start failed (") + e.what() + "): the fit starts from the initial values";
    return q0;
  }
}
}  // namespace

namespace {
// The lower half of the band's refit (frf_run.h): the fit again from q̂ on the lines up to the
// middle one, whose shift enters the interval as the half-record refit's does.
void half_band_refit(const Problem& p, FrfMisfit& m, const OptimizerOptions& o, RunResult& r, IntervalInputs& in) {
  const auto& f = p.frf->f_hz;
  if (f.size() < 4) {
    in.refit_applies = false;  // too few lines to halve: the noise and residual terms alone
    return;
  }
  io::FrfData lower = m.data();
  const std::size_t n = f.size() / 2;
  lower.f_hz.resize(n);
  for (auto& ch : lower.channels) {
    ch.H.resize(n);
    ch.variance.resize(n);
    if (ch.coherence.size() > n) ch.coherence.resize(n);
  }
  FrfMisfit lm(p.model(), *p.params, std::move(lower), m.sensors(), m.input());
  OptimizerOptions half = o;
  half.continuation = false;
  try {
    const OptimizerSummary s = minimize(lm, r.estimate, half);
    in.half_record_estimate = s.q;
    in.half_record_converged = s.converged();
    r.half_record_estimate = s.q;
    r.half_record_converged = s.converged();
  } catch (const std::domain_error&) {
    in.half_record_estimate = VectorXd::Constant(r.estimate.size(), std::nan(""));
    in.half_record_converged = false;
  }
}
}  // namespace

RunResult run_frf_identification(Problem& p, const RunOptions& ro) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto& id = p.scenario.identification;
  RunResult r = start_result(p, io::Model::Linear);
  FrfMisfit m(p.model(), *p.params, *p.frf, p.frf_sensors, p.frf_input);
  r.method = ro.method.value_or(id.method);
  if (r.method == io::Method::GaussNewtonKrylov)
    throw std::logic_error("run_frf_identification: gauss-newton-krylov (identify::check_run refuses it)");
  if (r.method == io::Method::Auto) r.method = io::Method::GaussNewton;
  OptimizerOptions o = optimizer_options(id, r.method, p.params->size(), ro.max_iterations);
  std::vector<IterationRecord> iterates;
  auto on_iteration = [&](const IterationRecord& it) {
    iterates.push_back(it);
    if (ro.verbose) print_iteration(p, it);
  };
  try {
    std::string start_note;
    const VectorXd q0 = peak_start(p, p.params->initial(), start_note);
    if (ro.verbose) io::progress("start: %s\n", start_note.c_str());
    r.frf_start_note = start_note;
    r.summary = minimize(m, q0, o, on_iteration);
    r.estimate = r.summary.q;
    r.fit = frf_fit_test(p, m, r.estimate);
    if (ro.verbose) io::progress("fit test: %s\n", r.fit.message.c_str());
    RunResult::Attempt a;
    a.strategy = "plain";
    a.method = r.method;
    a.termination = to_string(r.summary.termination);
    a.optimizer_converged = r.summary.converged();
    a.cost = m.cost(r.estimate);
    a.iterations = r.summary.iterations_done;
    a.explains_data = r.fit.explains_data;
    a.fit_message = r.fit.message;
    a.estimate = r.estimate;
    r.attempts.push_back(a);
    if (ro.compute_std) {
      const auto ti = std::chrono::steady_clock::now();
      const FisherInformation fi = frf_fisher(m, r.estimate);
      r.ident = identifiability_from(fi, r.estimate, &r.names);
      r.ident.noise_source = "frf";
      IntervalInputs in;
      in.estimate = r.estimate;
      half_band_refit(p, m, o, r, in);
      r.interval = uncertainty_interval(r.ident, in);
      flag_wide_intervals(r);
      r.identifiability_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - ti).count();
    }
  } catch (const io::Interrupted& e) {
    if (!ro.keep_interrupted || iterates.empty()) throw;
    io::clear_interrupt();
    const IterationRecord& last = iterates.back();
    r.summary.iterations = iterates;
    r.summary.q = last.q;
    r.summary.cost = last.cost;
    r.summary.iterations_done = last.k;
    r.summary.termination = OptimizerSummary::Termination::Interrupted;
    char note[200];
    std::snprintf(note, sizeof note, "%s at iteration %d: the last iterate reached, not converged",
                  e.signal() == SIGALRM ? "the wall-time limit" : e.signal() == SIGINT ? "SIGINT" : "SIGTERM", last.k);
    r.summary.message = note;
    r.estimate = last.q;
    r.fit = FitTest{};
    r.fit.message = std::string("not tested: ") + note;
    r.interrupted_by = e.signal();
    r.interrupted_note = note;
  }
  estimate_modes(p, r, ro.verbose);
  if (r.estimate.allFinite()) {
    m.set_horizon(m.data_end());
    r.frf_model = m.predict(r.estimate);
  }
  r.frf_passes = m.counters().evaluations;
  r.frf_factorisations = m.counters().factorisations;
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.summary.wall_seconds = r.wall_seconds;
  return r;
}

}  // namespace scoleid::identify
