// The identifier's front door for frequency-domain data (frf_door.h; docs/theory.md §6.10, §10.1b).
#include "scoleid/identify/door/frf_door.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <stdexcept>

#include "scoleid/io/error.h"
#include "scoleid/io/frf_estimate.h"

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

// The input and responses of samples [b, e) as arrays (the whole record for the lines' fit and an
// impact, chunks for Welch, which streams).
struct Samples {
  const Problem& p;
  int input;
  const std::string& name;  // the input's
  std::size_t n;            // the record's samples
  double fs;                // its sample rate [Hz]
  std::vector<double> x;
  std::vector<std::vector<double>> y;
  std::vector<const double*> yp;
  Samples(const Problem& problem, int in, double rate)
      : p(problem),
        input(in),
        name(problem.scenario.inputs[static_cast<std::size_t>(in)].name),
        n(problem.data.t.size()),
        fs(rate),
        y(static_cast<std::size_t>(problem.data.sensors())),
        yp(y.size()) {}
  void take(std::size_t b, std::size_t e) {
    x.resize(e - b);
    for (std::size_t i = b; i < e; ++i) x[i - b] = p.signals[static_cast<std::size_t>(input)](p.data.t[i]);
    for (std::size_t s = 0; s < y.size(); ++s) {
      y[s].resize(e - b);
      for (std::size_t i = b; i < e; ++i) y[s][i - b] = p.data.z(static_cast<Eigen::Index>(i), static_cast<int>(s));
      yp[s] = y[s].data();
    }
  }
};

// The lines estimator: the input's known lines fitted harmonically over the whole record.
void frf_lines(Problem& p, Samples& w, const std::vector<double>& signal_lines) {
  const auto& sc = p.scenario;
  const auto& spec = sc.identification.frf;
  const std::string& name = w.name;
  const std::size_t n = w.n;
  const double fs = w.fs;
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
  w.take(0, n);
  try {
    d = io::harmonic_frf(w.x.data(), w.yp, n, o, p.data_source, name, p.data.names);
  } catch (const std::invalid_argument& e) {
    throw io::InputError(p.data_source + ": identification.frf (lines): " + e.what());
  }
  p.frf_note = std::to_string(d.lines()) + " lines of input '" + name + "' fitted harmonically over " + io::format_value(p.data.t.back() - p.data.t.front()) + " s";
  finish_frf(p, std::move(d), 0.0);
}

// The impact estimator: one segment of the whole record under an exponential window on force and
// responses, the FRF at s = a + iω weighted by the sensors' noise levels (io/frf_estimate.h impact_frf).
void frf_impact(Problem& p, Samples& w) {
  const auto& sc = p.scenario;
  const auto& spec = sc.identification.frf;
  const std::string& name = w.name;
  const std::size_t n = w.n;
  const double fs = w.fs;
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
  w.take(0, n);
  o.decay = spec.decay >= 0 ? spec.decay : impact_decay(w.yp, n, fs, o.response_std);
  io::FrfData d;
  try {
    d = io::impact_frf(w.x.data(), w.yp, n, o, p.data_source, name, p.data.names);
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
}

// Welch's estimator (H1 or H2): averaged segments, streamed through the record in chunks.
void frf_welch(Problem& p, Samples& w, io::FrfEstimatorKind kind) {
  const auto& sc = p.scenario;
  const auto& spec = sc.identification.frf;
  const std::string& name = w.name;
  const std::size_t n = w.n;
  const double fs = w.fs;
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
  io::WelchFrf welch(p.data.sensors(), o);
  for (std::size_t b = 0; b < n; b += std::size_t{1} << 16) {
    const std::size_t e = std::min(n, b + (std::size_t{1} << 16));
    w.take(b, e);
    welch.add(w.x.data(), w.yp, e - b);
  }
  io::FrfData d;
  try {
    d = welch.result(p.data_source, name, p.data.names);
  } catch (const std::invalid_argument& e) {
    throw io::InputError(p.data_source + ": identification.frf: " + e.what());
  }
  const double dof = 2.0 * (effective_averages(welch.segments(), spec.window, spec.overlap) - 1.0);
  char note[200];
  std::snprintf(note, sizeof note, "Welch %s of input '%s': %d segments of %.4g s (%s, overlap %.2g), lines every %.4g Hz up to %.4g Hz",
                kind == io::FrfEstimatorKind::H2 ? "H2" : "H1", name.c_str(), welch.segments(), seg / fs, to_string(spec.window),
                spec.overlap, fs / seg, o.f_max);
  p.frf_note = note;
  finish_frf(p, std::move(d), dof);
}

}  // namespace

void frf_from_record(Problem& p) {
  const auto& sc = p.scenario;
  const auto& spec = sc.identification.frf;
  const int input = frf_input_index(p);
  Samples w(p, input, uniform_rate(p));
  bool only_lines = false;
  const std::vector<double> signal_lines = sc.inputs[static_cast<std::size_t>(input)].signal.lines(&only_lines);
  io::FrfEstimatorKind kind = spec.estimator;
  if (kind == io::FrfEstimatorKind::Auto) kind = (!spec.lines.empty() || only_lines) ? io::FrfEstimatorKind::Lines : io::FrfEstimatorKind::H1;
  if (kind == io::FrfEstimatorKind::Lines) frf_lines(p, w, signal_lines);
  else if (kind == io::FrfEstimatorKind::Impact) frf_impact(p, w);
  else frf_welch(p, w, kind);
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

}  // namespace scoleid::identify
