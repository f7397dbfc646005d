#include "scoleid/io/frf_record.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "scoleid/io/data_source.h"
#include "scoleid/io/error.h"
#include "scoleid/io/input_file.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/quiet_start.h"
#include "scoleid/io/time_grid.h"
#include "scoleid/io/units.h"
#include "scoleid/io/validation.h"

namespace scoleid::io {

namespace {

constexpr std::size_t kChunk = std::size_t{1} << 16;  // rows read at once; also the grid's sample

// The line breaks of a file: an upper bound of a CSV's rows, read at disk speed.
std::size_t count_lines(const std::string& path) {
  InputFileStream in(path, "data file '" + path + "'");
  std::vector<char> buf(std::size_t{1} << 20);
  std::size_t n = 0;
  while (in) {
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    const auto got = static_cast<std::size_t>(in.gcount());
    n += static_cast<std::size_t>(std::count(buf.data(), buf.data() + got, '\n'));
    check_interrupt();
  }
  return n + 1;
}

// One column's role: its index among the table's columns, its unit's scale into SI and order.
struct Column {
  int index = -1;
  double scale = 1.0;
  int order = 0;         // responses: 0 displacement, 1 velocity, 2 acceleration
  std::string name;      // the column's
  std::string unit;      // the unit read
  std::string replaced;  // the file's unit, when --unit replaced it
};

Column column(const std::string& source, const std::vector<std::string>& names, const std::vector<std::string>& units,
              const RecordFrfOptions& o, const std::string& name, const std::string& option, bool force) {
  Column c;
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) {
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "'" : ", '") + one_line(shorten(n, 40)) + "'";
    throw InputError(source + ": " + option + " names no column of the file (its columns: " + list + "), got '" + one_line(name) + "'");
  }
  c.index = static_cast<int>(it - names.begin());
  c.name = name;
  std::string unit = units[static_cast<std::size_t>(c.index)];
  // A unit given with --unit is the user's statement: it replaces the file's (a LabVIEW channel
  // left at its default label "g" that holds a force), and the note says so.
  const auto stated = o.units.find(name);
  if (stated != o.units.end()) {
    if (!unit.empty() && unit != stated->second) c.replaced = unit;
    unit = stated->second;
  }
  const std::string what = source + ": column '" + one_line(name) + "' (" + option + ")";
  if (unit.empty())
    throw InputError(what + ": the file states no unit; give it in the header ('" + one_line(name) + " [N]') or with --unit '" +
                     one_line(name) + "=UNIT'");
  c.unit = unit;
  using units::Quantity;
  if (force) {
    if (const auto why = units::problem_with(unit, Quantity::Force))
      throw InputError(what + ": the input must be a force: unit '" + one_line(unit) + "' " + *why);
    c.scale = units::conversion(unit, "N", Quantity::Force).scale;
    return c;
  }
  const struct { Quantity q; const char* si; int order; } kinds[] = {
      {Quantity::Acceleration, "m/s^2", 2}, {Quantity::Velocity, "m/s", 1}, {Quantity::Length, "m", 0}};
  for (const auto& k : kinds)
    if (!units::problem_with(unit, k.q)) {
      c.scale = units::conversion(unit, k.si, k.q).scale;
      c.order = k.order;
      return c;
    }
  throw InputError(what + ": a response must be a displacement, velocity or acceleration, got the unit '" + one_line(unit) + "'");
}

// The sample clock: the rate and t0 from the first chunk, each later time checked against them.
class Clock {
 public:
  // `step`, `rounding`: a step the file states for its times (DataTable::stated_step), or 0.
  Clock(std::string source, double stated, double step = 0, double rounding = 0)
      : source_(std::move(source)), stated_(stated), file_step_(step), file_rounding_(rounding) {}

  void add(const std::vector<double>& t) {
    if (t.empty()) return;
    if (step_ == 0) start(t);
    if (replaces_) {
      k_ += t.size();
      return;
    }
    const double tol = (stated_ > 0 ? 0.5 : 0.25) * step_;
    for (std::size_t i = 0; i < t.size(); ++i, ++k_) {
      const double off = t[i] - (t0_ + static_cast<double>(k_) * step_);
      if (!(std::abs(off) < tol))
        throw InputError(source_ + ": sample " + std::to_string(k_ + 1) + " (t = " + format_value(t[i]) + " s) lies " +
                         format_value(off / step_) + " steps off the clock t0 + k/" + format_value(1.0 / step_) + " Hz " + basis_ +
                         ": a dropped sample, a second segment or another rate" +
                         (stated_ > 0 ? std::string() : "; state --sample-rate if the clock is uniform"));
    }
  }
  double rate() const { return 1.0 / step_; }

 private:
  void start(const std::vector<double>& t) {
    if (t.size() < 2) throw InputError(source_ + ": needs at least 2 samples, got " + std::to_string(t.size()));
    if (stated_ > 0) {
      std::string why;
      const auto g = stated_grid(t, stated_, &why, file_step_, file_rounding_);
      if (!g) throw InputError(source_ + ": --sample-rate " + format_value(stated_) + ": " + why);
      t0_ = g->t0, step_ = g->step;
      basis_ = "(the stated rate)";
      // The file's own times t0 + k·(its written step): the rate replaces them, every sample.
      replaces_ = file_step_ > 0 && g->precision != "stated rate";
      return;
    }
    const TimeGrid g = uniform_grid(t);
    if (!g.uniform)
      throw InputError(source_ + ": the time column is not uniformly sampled: sample " + std::to_string(g.worst + 1) + " (t = " +
                       format_value(t[g.worst]) + " s) lies " + format_value(g.max_shift / g.step) + " steps off the grid of the first " +
                       std::to_string(t.size()) + " samples (written to " + g.precision + "); state --sample-rate if the clock is uniform");
    t0_ = g.t0, step_ = g.step;
    basis_ = "(fitted to the first " + std::to_string(t.size()) + " samples)";
  }

  std::string source_, basis_;
  double stated_ = 0, file_step_ = 0, file_rounding_ = 0, t0_ = 0, step_ = 0;
  bool replaces_ = false;
  std::size_t k_ = 0;
};

// The estimator fed chunk by chunk: Welch streams, lines keeps the samples.
class Feed {
 public:
  Feed(std::string source, const RecordFrfOptions& o, std::size_t expected, std::vector<Column> responses, Column input,
       double file_step = 0, double file_rounding = 0)
      : source_(std::move(source)), o_(o), expected_(expected), resp_(std::move(responses)), in_(input),
        clock_(source_, o.sample_rate, file_step, file_rounding) {
    x_.resize(resp_.size());
  }

  void add(const std::vector<double>& t, const std::vector<std::vector<double>>& cols) {
    const std::size_t n = t.size();
    if (n == 0) return;
    clock_.add(t);
    const std::vector<double>& x = cols[static_cast<std::size_t>(in_.index)];
    std::vector<const double*> y;
    for (const auto& r : resp_) y.push_back(cols[static_cast<std::size_t>(r.index)].data());
    if (o_.estimator == RecordFrfEstimator::Lines || o_.estimator == RecordFrfEstimator::Impact) {
      if (static_cast<double>(samples_ + n) > limits::kMaxSamples)
        throw InputError(source_ + ": more than " + format_value(limits::kMaxSamples) + " samples, the limit of a record the " +
                         (o_.estimator == RecordFrfEstimator::Lines ? "lines" : "impact") +
                         " estimator holds whole (Welch streams any length)");
      input_.insert(input_.end(), x.begin(), x.end());
      for (std::size_t s = 0; s < resp_.size(); ++s) x_[s].insert(x_[s].end(), y[s], y[s] + n);
    } else {
      if (!welch_) start_welch();
      welch_->add(x.data(), y, n);
    }
    const std::size_t before = samples_;
    samples_ += n;
    if (o_.progress && (before >> 20) != (samples_ >> 20)) o_.progress(samples_);
  }

  RecordFrf finish(const std::string& input_name, const std::vector<std::string>& names) {
    RecordFrf r;
    r.samples = samples_;
    if (samples_ < 16) throw InputError(source_ + ": " + std::to_string(samples_) + " samples are too few for frequency responses");
    r.sample_rate = clock_.rate();
    const double fs = r.sample_rate;
    char note[400];
    try {
      if (o_.estimator == RecordFrfEstimator::Lines) {
        LinesOptions lo;
        lo.sample_rate = fs;
        lo.lines_hz = o_.lines_hz;
        std::vector<const double*> y;
        for (const auto& v : x_) y.push_back(v.data());
        r.data = harmonic_frf(input_.data(), y, samples_, lo, source_, input_name, names);
        r.effective_averages = r.data.averages;
        std::snprintf(note, sizeof note, "%d lines fitted harmonically over %.6g s at %.6g Hz", r.data.lines(),
                      static_cast<double>(samples_) / fs, fs);
      } else if (o_.estimator == RecordFrfEstimator::Impact) {
        impact(r, input_name, names, note, sizeof note);
      } else {
        if (!welch_) start_welch();
        r.data = welch_->result(source_, input_name, names);
        r.segments = welch_->segments();
        r.effective_averages = welch_effective_averages(r.segments, o_.window, o_.overlap);
        std::snprintf(note, sizeof note,
                      "Welch %s: %d segments of %ld samples (%.6g s, %s, overlap %.2g; %.1f effective averages), lines every %.6g Hz up to %.6g Hz",
                      o_.estimator == RecordFrfEstimator::H2 ? "H2" : "H1", r.segments, segment_, segment_ / fs,
                      o_.window == FrfWindow::Hann ? "Hann" : "rectangular", o_.overlap, r.effective_averages, fs / segment_,
                      r.data.f_hz.empty() ? 0.0 : r.data.f_hz.back());
      }
    } catch (const std::invalid_argument& e) {
      throw InputError(source_ + ": " + e.what());
    }
    r.note = note;
    for (const Column* c : [&] {
           std::vector<const Column*> all{&in_};
           for (const auto& x : resp_) all.push_back(&x);
           return all;
         }())
      if (!c->replaced.empty())
        r.note += "; column '" + one_line(c->name) + "' read in " + c->unit + " (--unit; the file says " + c->replaced + ")";
    // Into SI: the estimators are linear in each column.
    for (std::size_t s = 0; s < resp_.size(); ++s) {
      const double c = resp_[s].scale / in_.scale;
      for (auto& h : r.data.channels[s].H) h *= c;
      for (auto& v : r.data.channels[s].variance) v *= c * c;
      r.orders.push_back(resp_[s].order);
    }
    return r;
  }

 private:
  void start_welch() {
    const double fs = clock_.rate();
    WelchOptions w;
    w.sample_rate = fs;
    w.overlap = o_.overlap;
    w.window = o_.window;
    w.estimator = o_.estimator == RecordFrfEstimator::H2 ? FrfEstimator::H2 : FrfEstimator::H1;
    w.f_min = o_.f_min;
    w.f_max = o_.f_max > 0 ? o_.f_max : 0.8 * 0.5 * fs;
    segment_ = o_.segment > 0 ? std::lround(o_.segment * fs)
                              : 1L << static_cast<int>(std::floor(std::log2(std::max(2.0, static_cast<double>(expected_) / 4.5))));
    if (segment_ < 16)
      throw InputError(source_ + ": --segment " + format_value(o_.segment) + " s holds " + std::to_string(segment_) +
                       " samples at " + format_value(fs) + " Hz; a segment needs at least 16");
    w.segment = segment_;
    try {
      welch_ = std::make_unique<WelchFrf>(static_cast<int>(resp_.size()), w);
    } catch (const std::invalid_argument& e) {
      throw InputError(source_ + ": " + e.what());
    }
  }

  // The impact estimator on the samples kept: each response's noise stated or its quiet start's.
  void impact(RecordFrf& r, const std::string& input_name, const std::vector<std::string>& names, char* note, std::size_t size) {
    const double fs = r.sample_rate;
    const double T = static_cast<double>(samples_) / fs;
    ImpactOptions io;
    io.sample_rate = fs;
    io.decay = o_.decay >= 0 ? o_.decay : std::log(100.0) / T;
    io.f_max = o_.f_max > 0 ? o_.f_max : 0.8 * 0.5 * fs;
    // The trigger about the force's median (a hammer's record is mostly rest: its median is the
    // channel's static offset, which would otherwise count toward a twentieth of the peak).
    std::vector<double> about = input_;
    std::nth_element(about.begin(), about.begin() + static_cast<std::ptrdiff_t>(samples_ / 2), about.end());
    const double median = about[samples_ / 2];
    for (std::size_t i = 0; i < samples_; ++i) about[i] = input_[i] - median;
    const std::size_t trigger = trigger_sample(about.data(), samples_), quiet = quiet_samples(trigger);
    int estimated = 0;
    for (std::size_t s = 0; s < resp_.size(); ++s) {
      const auto it = o_.noise.find(names[s]);
      double sd = it != o_.noise.end() ? it->second : quiet_start_noise(x_[s].data(), quiet);
      if (!(sd > 0)) {
        const std::string why =
            trigger >= samples_ ? "the input never acts"
            : quiet == 0 ? std::to_string(trigger) + " samples precede the hit (at t = " + format_value(static_cast<double>(trigger) / fs) +
                               " s after the first), fewer than " + std::to_string(kQuietSamples + kQuietMargin)
                         : "its quiet start reads exactly zero";
        throw InputError(source_ + ": column '" + one_line(names[s]) +
                         "' has no noise level for the impact estimator (one hit's FRF has no scatter to weigh it by) and its quiet start "
                         "gives none (" + why + "); state --noise '" + one_line(names[s]) + "=SIGMA' in the column's unit");
      }
      if (it == o_.noise.end()) ++estimated;
      io.response_std.push_back(sd);
    }
    if (const auto it = o_.noise.find(input_name); it != o_.noise.end()) io.input_std = it->second;
    // A channel's static offset (a load cell's, a converter's) would be read as force or response over
    // the whole window, and under e^{-at} it dominates the low lines: with a quiet start, each
    // channel's mean there is removed first.
    auto remove_offset = [quiet](std::vector<double>& v) {
      double mean = 0.0;
      for (std::size_t i = 0; i < quiet; ++i) mean += v[i] / static_cast<double>(quiet);
      for (double& x : v) x -= mean;
    };
    if (quiet > 0) {
      remove_offset(input_);
      for (auto& v : x_) remove_offset(v);
    }
    std::vector<const double*> y;
    for (const auto& v : x_) y.push_back(v.data());
    r.data = impact_frf(input_.data(), y, samples_, io, source_, input_name, names);
    if (o_.f_min > 0) drop_lines_below(r.data, o_.f_min);
    r.effective_averages = 1;
    std::snprintf(note, size,
                  "impact: one segment of %.6g s under e^{-%.6g t} (%.3g at its end), H at s = %.6g + i omega, lines every %.6g Hz up to "
                  "%.6g Hz; %d of %zu noise levels from the quiet start (%zu samples)%s",
                  T, io.decay, std::exp(-io.decay * T), io.decay, fs / static_cast<double>(samples_),
                  r.data.f_hz.empty() ? 0.0 : r.data.f_hz.back(), estimated, resp_.size(), quiet,
                  quiet > 0 ? ", each channel's mean there removed" : ", no quiet start: offsets kept");
  }

  // Lines at or below f_min removed (the impact estimator keeps every line from fs/N).
  static void drop_lines_below(FrfData& d, double f_min) {
    std::size_t k = 0;
    while (k < d.f_hz.size() && !(d.f_hz[k] > f_min)) ++k;
    const auto cut = [k](auto& v) {
      if (v.size() >= k) v.erase(v.begin(), v.begin() + static_cast<long>(k));
    };
    cut(d.f_hz);
    for (auto& ch : d.channels) {
      cut(ch.H);
      cut(ch.variance);
      if (!ch.coherence.empty()) cut(ch.coherence);
    }
  }

  std::string source_;
  const RecordFrfOptions& o_;
  std::size_t expected_, samples_ = 0;
  std::vector<Column> resp_;
  Column in_;
  Clock clock_;
  std::unique_ptr<WelchFrf> welch_;
  long segment_ = 0;
  std::vector<double> input_;
  std::vector<std::vector<double>> x_;
};

void check_options(const RecordFrfOptions& o) {
  if (o.input.empty()) throw InputError("command line: --input must name the force column");
  if (!(o.sample_rate >= 0) || !std::isfinite(o.sample_rate))
    throw InputError("command line: --sample-rate must be positive (Hz), got " + format_value(o.sample_rate));
  if (!(o.segment >= 0) || !std::isfinite(o.segment))
    throw InputError("command line: --segment must be positive (s), got " + format_value(o.segment));
  if (!(o.overlap >= 0 && o.overlap < 1)) throw InputError("command line: --overlap must lie in [0, 1), got " + format_value(o.overlap));
  if (!(o.f_min >= 0) || !(o.f_max >= 0) || !std::isfinite(o.f_min) || !std::isfinite(o.f_max) || (o.f_max > 0 && o.f_max <= o.f_min))
    throw InputError("command line: --f-min and --f-max must satisfy 0 <= f-min < f-max, got " + format_value(o.f_min) + " and " +
                     format_value(o.f_max));
  if (o.estimator == RecordFrfEstimator::Lines) {
    if (o.lines_hz.empty()) throw InputError("command line: --lines must list the frequencies (Hz) for the lines estimator");
    for (std::size_t k = 0; k < o.lines_hz.size(); ++k)
      if (!(o.lines_hz[k] > (k ? o.lines_hz[k - 1] : 0.0)) || !std::isfinite(o.lines_hz[k]))
        throw InputError("command line: --lines must be positive and strictly increasing, got " + format_value(o.lines_hz[k]));
  } else if (!o.lines_hz.empty()) {
    throw InputError("command line: --lines is for --estimator lines");
  }
  if (o.estimator == RecordFrfEstimator::Impact) {
    if (!std::isfinite(o.decay) || (o.decay < 0 && o.decay != -1.0))
      throw InputError("command line: --decay must be a rate >= 0 (1/s), got " + format_value(o.decay));
    for (const auto& [name, sd] : o.noise)
      if (!(sd > 0) || !std::isfinite(sd))
        throw InputError("command line: --noise '" + one_line(name) + "' must be a positive level, got " + format_value(sd));
  } else if (o.decay != -1.0 || !o.noise.empty()) {
    throw InputError(std::string("command line: ") + (o.decay != -1.0 ? "--decay" : "--noise") + " is for --estimator impact");
  }
}

}  // namespace

RecordFrf frf_of_record(const std::string& path, const CsvOptions& csv, const RecordFrfOptions& o) {
  check_options(o);
  const std::string source = "data file '" + path + "'";
  auto roles = [&](const std::vector<std::string>& names, const std::vector<std::string>& units, std::vector<Column>& resp,
                   std::vector<std::string>& resp_names) {
    for (const auto& [name, unit] : o.units)
      if (std::find(names.begin(), names.end(), name) == names.end())
        throw InputError("command line: --unit names no column of " + source + ", got '" + one_line(name) + "'");
    for (const auto& [name, sd] : o.noise)
      if (std::find(names.begin(), names.end(), name) == names.end())
        throw InputError("command line: --noise names no column of " + source + ", got '" + one_line(name) + "'");
    const Column in = column(source, names, units, o, o.input, "--input", true);
    resp_names = o.responses;
    if (resp_names.empty())
      for (const auto& n : names)
        if (n != o.input) resp_names.push_back(n);
    for (const auto& n : resp_names) {
      if (n == o.input) throw InputError("command line: --response '" + one_line(n) + "' is the input column");
      if (std::count(resp_names.begin(), resp_names.end(), n) > 1)
        throw InputError("command line: --response names column '" + one_line(n) + "' twice");
      resp.push_back(column(source, names, units, o, n, "--response", false));
    }
    if (resp.empty()) throw InputError(source + ": no response column beside the input '" + one_line(o.input) + "'");
    return in;
  };
  std::vector<Column> resp;
  std::vector<std::string> resp_names;
  if (is_csv_data(path)) {
    CsvData d = open_csv_data(path, csv);
    const Column in = roles(d.reader->header().names, d.units, resp, resp_names);
    const std::size_t expected = o.segment > 0 ? 0 : count_lines(path);
    Feed feed(source, o, expected, resp, in);
    std::vector<double> t;
    std::vector<std::vector<double>> cols;
    while (d.reader->read(kChunk, t, cols) > 0) feed.add(t, cols);
    return feed.finish(o.input, resp_names);
  }
  const DataTable tab = read_data(path, csv);
  std::vector<std::string> units = tab.units;
  units.resize(tab.names.size());
  const Column in = roles(tab.names, units, resp, resp_names);
  Feed feed(source, o, tab.t.size(), resp, in, tab.stated_step, tab.stated_step_rounding);
  std::vector<double> t;
  std::vector<std::vector<double>> cols(tab.names.size());
  for (std::size_t b = 0; b < tab.t.size(); b += kChunk) {
    const std::size_t e = std::min(tab.t.size(), b + kChunk);
    t.assign(tab.t.begin() + static_cast<long>(b), tab.t.begin() + static_cast<long>(e));
    for (std::size_t j = 0; j < cols.size(); ++j)
      cols[j].assign(tab.columns[j].begin() + static_cast<long>(b), tab.columns[j].begin() + static_cast<long>(e));
    feed.add(t, cols);
    check_interrupt();
  }
  return feed.finish(o.input, resp_names);
}

}  // namespace scoleid::io
