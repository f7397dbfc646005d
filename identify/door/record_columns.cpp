// A record's columns read for the scenario's sensors and inputs (record_columns.h).
#include "scoleid/identify/door/record_columns.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "scoleid/io/error.h"
#include "scoleid/io/number.h"
#include "scoleid/io/units.h"
#include "scoleid/io/validation.h"

namespace scoleid::identify {

using io::InputError;

namespace {

// A sensor's record with one sample over kLoneSpike times the RMS of all its others: no
// structure's response does that (a response spreads over the samples its modes last; even a
// step near the record's end keeps the peak within ten times the RMS), so it is a spike, a
// corrupted cell or a unit slip in one row (a 1e23 m sample), and a least-squares fit would
// chase it. Refused, naming the sample.
constexpr double kLoneSpike = 1e3;
void check_lone_spike(const std::vector<double>& v, const io::DataTable& tab, int col, const std::string& field,
                      const std::string& name) {
  if (v.size() < 30) return;
  std::size_t peak = 0;
  for (std::size_t k = 1; k < v.size(); ++k)
    if (std::abs(v[k]) > std::abs(v[peak])) peak = k;
  double ms = 0.0;
  for (std::size_t k = 0; k < v.size(); ++k)
    if (k != peak) ms += v[k] * v[k];
  const double rest = std::sqrt(ms / static_cast<double>(v.size() - 1));
  if (!(std::abs(v[peak]) > kLoneSpike * rest)) return;
  throw InputError("data file '" + tab.source + "': column '" + io::one_line(tab.names[static_cast<std::size_t>(col)]) +
                   "' (" + field + ", sensor '" + name + "'): the sample at t = " + io::format_value(tab.t[peak]) + " s is " +
                   io::format_value(v[peak]) + ", over " + io::format_value(kLoneSpike) +
                   " times the RMS of the column's other samples (" + io::format_value(rest) +
                   "): a spike, a corrupted cell or a unit slip that a least-squares fit would chase; correct or remove it");
}

// A header without its unit suffix ("acc [m/s^2]" → "acc"); the header itself when it states none.
std::string name_without_unit(const std::string& header) {
  if (io::units::bracketed_unit(header).empty()) return header;
  const auto e = header.find_last_not_of(" \t");
  const auto open = header.rfind(header[e] == ']' ? '[' : '(', e);
  const auto end = header.find_last_not_of(" \t", open == 0 ? std::string::npos : open - 1);
  return open == 0 || end == std::string::npos ? std::string() : header.substr(0, end + 1);
}

// The table column of a sensor or input: its `column` (exactly), else its name — a column of that
// name, or the one column that is that name with a unit ("acc [m/s^2]" for a sensor acc: labs write
// units into headers); -1 when absent. Two columns that are the name with units are refused.
int column_of(const io::DataTable& tab, const std::string& name, const std::string& column, const std::string& csv,
              const std::string& field) {
  if (!column.empty()) return tab.find(column);
  if (const int exact = tab.find(name); exact >= 0) return exact;
  int found = -1;
  for (std::size_t c = 0; c < tab.names.size(); ++c) {
    if (name_without_unit(tab.names[c]) != name) continue;
    if (found >= 0)
      throw InputError("data file '" + csv + "': columns '" + io::one_line(tab.names[static_cast<std::size_t>(found)]) + "' and '" +
                       io::one_line(tab.names[c]) + "' are both '" + name + "' with a unit; name one in " + field + ".column");
    found = static_cast<int>(c);
  }
  return found;
}

// The table's columns, for a message (the first 12).
std::string columns_listed(const io::DataTable& tab) {
  std::string s;
  for (std::size_t c = 0; c < tab.names.size() && c < 12; ++c) s += (c ? ", '" : "'") + io::one_line(tab.names[c]) + "'";
  if (tab.names.size() > 12) s += ", ... (" + std::to_string(tab.names.size()) + " in all)";
  return s;
}

// The values of column `col` in the unit of a sensor or input of kind `kind` and unit `unit`
// (or its unit system's): the column's unit from column_unit, else from its file. A column without
// a stated unit is taken as it is; one with a unit needs a unit to convert into.
// The column conditioned as the scenario says (io::Conditioning): x' = sign·scale·(x − offset), then
// less its least-squares line with detrend; what was removed is recorded in `src`.
void condition(std::vector<double>& v, const std::vector<double>& t, const io::Conditioning& c, const std::string& where,
               const std::string& field, ColumnUse::Source& src) {
  if (!c.transforms()) return;
  double offset = 0.0;
  switch (c.offset) {
    case io::Conditioning::Offset::None: break;
    case io::Conditioning::Offset::Value: offset = c.offset_value; break;
    case io::Conditioning::Offset::Mean:
      for (double x : v) offset += x / static_cast<double>(v.size());
      break;
    case io::Conditioning::Offset::MeanBefore: {
      std::size_t n = 0;
      while (n < t.size() && t[n] < c.offset_value) ++n;
      if (n == 0)
        throw InputError(where + ": " + field + ".conditioning.offset.mean_before " + io::format_value(c.offset_value) +
                         " s leaves no sample before it (the record starts at " + io::format_value(t.front()) + " s)");
      if (n == t.size())
        throw InputError(where + ": " + field + ".conditioning.offset.mean_before " + io::format_value(c.offset_value) +
                         " s takes the whole record (it ends at " + io::format_value(t.back()) + " s): use offset: mean");
      for (std::size_t k = 0; k < n; ++k) offset += v[k] / static_cast<double>(n);
      break;
    }
  }
  const double factor = c.sign * c.scale;
  for (double& x : v) x = factor * (x - offset);
  double slope = 0.0, mean = 0.0;
  if (c.detrend) {
    // Least-squares line a + b (t − t̄).
    double tm = 0.0;
    for (std::size_t k = 0; k < v.size(); ++k) {
      tm += t[k] / static_cast<double>(v.size());
      mean += v[k] / static_cast<double>(v.size());
    }
    double stt = 0.0, sty = 0.0;
    for (std::size_t k = 0; k < v.size(); ++k) {
      stt += (t[k] - tm) * (t[k] - tm);
      sty += (t[k] - tm) * (v[k] - mean);
    }
    slope = stt > 0 ? sty / stt : 0.0;
    for (std::size_t k = 0; k < v.size(); ++k) v[k] -= mean + slope * (t[k] - tm);
  }
  src.conditioned = true;
  src.offset_removed = offset;
  src.factor = factor;
  src.trend_removed = {mean, slope};
}

std::vector<double> column_values(Problem& p, const io::DataTable& tab, int col, const std::string& field,
                                  const std::string& name, const std::string& kind, const std::string& unit,
                                  const std::string& column_unit, const io::Conditioning& conditioning) {
  const auto& sc = p.scenario;
  const std::string& column = tab.names[static_cast<std::size_t>(col)];
  ColumnUse::Source src{name, column, column_unit.empty() ? tab.unit(col) : column_unit,
                        column_unit.empty() ? "file" : field + ".column_unit", unit, 1.0};
  const auto q = io::units::quantity_of_kind(kind);
  if (src.to_unit.empty() && q) src.to_unit = io::units::system_unit(sc.units, *q);
  // A column its file gives no unit takes the one truth.json beside it states, when the scenario
  // states a unit to read it in (without one, values are taken as they are, as from any file).
  if (const auto it = p.meta_units.find(column);
      src.from_unit.empty() && it != p.meta_units.end() && !src.to_unit.empty() && it->second != src.to_unit) {
    src.from_unit = it->second;
    src.unit_stated_by = "truth.json";
  }
  std::vector<double> v = tab.columns[static_cast<std::size_t>(col)];
  const std::string where = "data file '" + tab.source + "': column '" + io::one_line(column) + "' (" + field + ", '" + name + "')";
  if (src.from_unit.empty() || !q) {
    src.unit_stated_by = src.from_unit.empty() ? "none" : src.unit_stated_by;
    condition(v, tab.t, conditioning, where, field, src);
    p.columns.sources.push_back(src);
    return v;
  }
  if (src.to_unit.empty())
    throw InputError(where + ": is in '" + src.from_unit + "' but " + field +
                     " states no unit to convert it into: give " + field + ".unit or the scenario's units");
  io::units::Conversion c;
  try {
    c = io::units::conversion(src.from_unit, src.to_unit, *q);
  } catch (const std::invalid_argument& e) {
    throw InputError(where + ": cannot convert '" + src.from_unit + "' into '" + src.to_unit + "': " + e.what());
  }
  src.scale = c.scale;
  if (!c.identity())
    for (double& x : v) x = c.apply(x);
  condition(v, tab.t, conditioning, where, field, src);
  p.columns.sources.push_back(src);
  return v;
}

// A pulse over at most this many samples (above a tenth of its peak) is an impact.
constexpr int kImpactSamples = 8;
bool add_stepped_input(Problem& p, const io::InputSpec& in, const io::DataTable& tab, const std::vector<double>& f);

// An input driven by its column, read between samples as inputs[i].interpolation says (auto:
// cubic unless the column jumps, then piecewise linear), with its largest jump within one sample.
// An input column's force window (io::Conditioning::Window; docs/data.md §2). A force transducer
// reads noise before and after a hit, and a model driven by it answers that noise (at an
// accelerometer, whose response to force has a direct term, as much as to the hit). Auto, on an
// impact (add_stepped_input: a pulse over at most kImpactSamples samples): the channel's noise σ_f
// is read where it holds no force — at least 20 samples before the pulse, else the record's last
// quarter when that lies after it; the window runs from before the pulse's first sample above a
// twentieth of its peak, back to where the column falls to 4σ_f, to the start of the first run of
// 20 samples under 4σ_f after its last (a DAQ filter's ringing is force the accelerometers felt, and
// stays in); outside it the column is zero. A clean column (σ_f = 0) is thus left as it is, and so
// is one whose level outside the window is not small (RMS over a twentieth of the peak: an offset
// not removed, a continuous force). The hits are the runs above a fifth of the peak, apart by at
// least two samples under a twentieth. Span keeps [from, to] s. What was done is recorded in `st`.
void force_window(const io::InputSpec& in, const std::string& field, const io::DataTable& tab, std::vector<double>& f,
                  ColumnUse::SteppedInput* st, const std::string& csv) {
  const auto& c = in.conditioning;
  const auto& t = tab.t;
  if (c.window == io::Conditioning::Window::Span) {
    std::size_t kept = 0;
    for (std::size_t k = 0; k < f.size(); ++k)
      if (t[k] < c.window_from || t[k] > c.window_to) f[k] = 0.0;
      else ++kept;
    if (kept == 0)
      throw InputError("data file '" + csv + "': " + field + ".conditioning.window [" + io::format_value(c.window_from) + ", " +
                       io::format_value(c.window_to) + "] s holds no sample of the record (" + io::format_value(t.front()) + " .. " +
                       io::format_value(t.back()) + " s)");
    return;
  }
  if (c.window != io::Conditioning::Window::Auto || !st || st->pulse_samples == 0) return;
  const std::size_t n = f.size();
  double peak = 0.0;
  for (double x : f) peak = std::max(peak, std::abs(x));
  if (!(peak > 0)) return;
  std::size_t a = n, b = 0;
  for (std::size_t k = 0; k < n; ++k)
    if (std::abs(f[k]) > 0.05 * peak) a = std::min(a, k), b = k;
  // The channel's noise where it holds no force.
  constexpr std::size_t kNoiseSamples = 20, kQuietRun = 20;
  auto rms = [&](std::size_t from, std::size_t to) {  // about the mean, samples [from, to)
    double m = 0.0, s = 0.0;
    for (std::size_t k = from; k < to; ++k) m += f[k] / static_cast<double>(to - from);
    for (std::size_t k = from; k < to; ++k) s += (f[k] - m) * (f[k] - m) / static_cast<double>(to - from);
    return std::sqrt(s);
  };
  double sigma = -1.0;
  if (a >= kNoiseSamples + 4) sigma = rms(0, a - 4);
  else if (3 * n / 4 > b + kQuietRun) sigma = rms(3 * n / 4, n);
  if (!(sigma >= 0.0)) return;
  const double level = 4.0 * sigma;
  std::size_t from = a;
  while (from > 0 && std::abs(f[from - 1]) > level) --from;
  from = from >= 2 ? from - 2 : 0;
  std::size_t to = n - 1, run = 0;
  for (std::size_t k = b + 1; k < n; ++k) {
    run = std::abs(f[k]) <= level ? run + 1 : 0;
    if (run == kQuietRun) {
      to = k - kQuietRun + 1;
      break;
    }
  }
  double outside = 0.0;
  std::size_t n_out = 0;
  for (std::size_t k = 0; k < n; ++k)
    if (k < from || k > to) outside += f[k] * f[k], ++n_out;
  if (n_out == 0 || std::sqrt(outside / static_cast<double>(n_out)) > 0.05 * peak) return;
  // The hits: runs above a fifth of the peak, apart by at least two samples under a twentieth.
  std::size_t quiet = 2;
  for (std::size_t k = a; k <= b; ++k) {
    const double x = std::abs(f[k]);
    if (x > 0.2 * peak) {
      if (quiet >= 2) st->hits.push_back({t[k], x / peak});
      else if (x / peak > st->hits.back().second) st->hits.back() = {t[k], x / peak};
      quiet = 0;
    } else if (x < 0.05 * peak) {
      ++quiet;
    }
  }
  for (std::size_t k = 0; k < n; ++k)
    if (k < from || k > to) f[k] = 0.0;
  st->window_from = t[from];
  st->window_to = t[to];
  st->windowed = true;
}

void input_from_column(Problem& p, std::size_t i, const io::DataTable& tab, int col, const std::string& csv) {
  const auto& in = p.scenario.inputs[i];
  const std::string field = "inputs[" + std::to_string(i) + "]";
  auto f = column_values(p, tab, col, field, in.name, io::to_string(in.kind), in.unit, in.column_unit, in.conditioning);
  p.columns.inputs_from_data.push_back(in.name);
  const bool stepped = add_stepped_input(p, in, tab, f);
  force_window(in, field, tab, f, stepped ? &p.columns.stepped_inputs.back() : nullptr, csv);
  const bool cubic = in.interpolation == io::Interpolation::Cubic || (in.interpolation == io::Interpolation::Auto && !stepped);
  p.signals[i] = cubic ? io::Signal::cubic_table(tab.t, f) : io::Signal::table(tab.t, f);
  if (stepped) p.columns.stepped_inputs.back().cubic = cubic;
  p.columns.input_interpolation.push_back(cubic ? io::Interpolation::Cubic : io::Interpolation::Linear);
}

// Whether the column jumps by more than a quarter of its range within one sample, in a step (a
// change more than three times either neighbour's) or an impact (a pulse over a few samples); if it
// does, it is listed among the stepped inputs (ColumnUse), its largest jump and where.
bool add_stepped_input(Problem& p, const io::InputSpec& in, const io::DataTable& tab, const std::vector<double>& f) {
  const auto [lo, hi] = std::minmax_element(f.begin(), f.end());
  ColumnUse::SteppedInput st;
  st.name = in.name;
  st.scenario_signal = !in.signal.terms().empty();
  std::size_t at = 0;
  for (std::size_t k = 1; k < f.size(); ++k)
    if (std::abs(f[k] - f[k - 1]) > st.jump) {
      st.jump = std::abs(f[k] - f[k - 1]);
      st.at = tab.t[k];
      st.sample = tab.t[k] - tab.t[k - 1];
      at = k;
    }
  if (!(*hi > *lo && st.jump > 0.25 * (*hi - *lo))) return false;
  if (std::abs(f.back() - f.front()) < 0.25 * (*hi - *lo)) {
    const double peak = std::max(std::abs(*hi - f.front()), std::abs(*lo - f.front()));
    st.pulse_samples = static_cast<int>(
        std::count_if(f.begin(), f.end(), [&](double x) { return std::abs(x - f.front()) > 0.1 * peak; }));
  }
  // A jump (a change with a neighbour under a third of it: a step, one caught mid-way, a switch),
  // or an impact over a few samples; not a smooth signal sampled a few times a period (a sampled
  // harmonic's largest change has both neighbours at cos(ω Δt) of it, over a third above 5.1
  // samples a period).
  const double before = at >= 2 ? std::abs(f[at - 1] - f[at - 2]) : 0.0;
  const double after = at + 1 < f.size() ? std::abs(f[at + 1] - f[at]) : 0.0;
  const bool isolated = st.jump > 3.0 * std::min(before, after);
  const bool impact = st.pulse_samples > 0 && st.pulse_samples <= kImpactSamples;
  if (!isolated && !impact) return false;
  p.columns.stepped_inputs.push_back(st);
  return true;
}

}  // namespace

// The measurements from the table's sensor columns, the inputs from theirs (signal_from), and
// which columns were used (ColumnUse).
void measurements_from_table(Problem& p, const io::DataTable& tab, const std::string& csv) {
  const auto& sc = p.scenario;
  p.data.t = tab.t;
  p.data.z.resize(static_cast<Eigen::Index>(tab.t.size()), static_cast<Eigen::Index>(sc.sensors.size()));
  std::vector<bool> used(tab.names.size(), false);
  for (std::size_t j = 0; j < sc.sensors.size(); ++j) {
    const auto& s = sc.sensors[j];
    const std::string field = "sensors[" + std::to_string(j) + "]";
    const int col = column_of(tab, s.name, s.column, csv, field);
    if (col < 0)
      throw InputError("data file '" + csv + "': no column " +
                       (s.column.empty() ? "for sensor '" + s.name + "'" : "'" + io::one_line(s.column) + "' (" + field + ".column)") +
                       " (" + field + " of " + sc.source + "); its columns: " + columns_listed(tab));
    const auto v = column_values(p, tab, col, field, s.name, io::to_string(s.kind), s.unit, s.column_unit, s.conditioning);
    check_lone_spike(v, tab, col, field, s.name);
    for (std::size_t k = 0; k < tab.t.size(); ++k) p.data.z(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)) = v[k];
    p.data.names.push_back(s.name);
    used[static_cast<std::size_t>(col)] = true;
    p.columns.sensors.push_back(s.name);
  }
  for (std::size_t i = 0; i < sc.inputs.size(); ++i) {
    const auto& in = sc.inputs[i];
    const std::string field = "inputs[" + std::to_string(i) + "]";
    const int col = column_of(tab, in.name, in.column, csv, field);
    if ((in.signal_from == io::SignalFrom::Data || !in.column.empty()) && col < 0)
      throw InputError("data file '" + csv + "': no column " +
                       (in.column.empty() ? "for input '" + in.name + "'" : "'" + io::one_line(in.column) + "' (" + field + ".column)") +
                       " (" + field + (in.column.empty() ? ".signal_from is data" : "") + ", in " + sc.source + "); its columns: " +
                       columns_listed(tab));
    if (in.signal_from != io::SignalFrom::Scenario && col >= 0) {
      input_from_column(p, i, tab, col, csv);
      used[static_cast<std::size_t>(col)] = true;
    } else {
      if (in.signal.terms().empty())
        throw InputError("data file '" + csv + "': no column for input '" + in.name + "' and " + field + " of " + sc.source +
                         " gives no signal");
      p.columns.inputs_from_scenario.push_back(in.name);
    }
  }
  for (std::size_t c = 0; c < tab.names.size(); ++c)
    if (!used[c]) p.columns.unused.push_back(tab.names[c]);
  if (tab.t.size() < 3)
    throw InputError("data file '" + csv + "': " + std::to_string(tab.t.size()) + " rows: at least 3 samples are needed");
  if (tab.t.front() < 0.0)
    throw InputError("data file '" + csv + "': first time must be >= 0, got " + io::format_value(tab.t.front()));
  p.data_source = csv;
}

}  // namespace scoleid::identify
