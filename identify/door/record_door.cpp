// The identifier's front door for a record (record_door.h; docs/theory.md §10.1b).
#include "scoleid/identify/door/record_door.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "scoleid/identify/door/record_columns.h"
#include "scoleid/io/error.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/quiet_start.h"
#include "scoleid/io/time_grid.h"
#include "scoleid/io/validation.h"

namespace scoleid::identify {

using io::fail_field;
using io::InputError;

namespace {

// Truth metadata beside the data (truth.json): the two must describe the same columns; its noise
// levels stand for sensors without a stated one. Returns its true parameters.
std::map<std::string, double> apply_truth_meta(Problem& p, const io::DataTable& tab, const std::string& csv,
                                               const io::TruthMeta& meta, const std::string& meta_path) {
  const auto& sc = p.scenario;
  std::vector<std::string> described;
  for (const auto& c : meta.columns) described.push_back(c.name);
  for (const auto& n : tab.names)
    if (std::find(described.begin(), described.end(), n) == described.end())
      throw InputError(meta_path + ": does not describe column '" + n + "' of data file '" + csv +
                       "'; the two files are not from the same run");
  for (const auto& n : described)
    if (tab.find(n) < 0)
      throw InputError(meta_path + ": describes column '" + n + "', which data file '" + csv +
                       "' lacks; the two files are not from the same run");
  // The structure, and each column's quantity, site and unit, as the scenario has them: a truth of
  // another structure, a force read as a moment, a sensor on another body, or values in another
  // unit would be identified without a word.
  const std::string structure = io::to_string(sc.structure);
  if (!meta.structure.empty() && meta.structure != structure)
    throw InputError(meta_path + ": structure '" + meta.structure + "' but the scenario's is '" + structure +
                     "'; the data are not of this scenario's structure");
  for (const auto& c : meta.columns) {
    std::optional<std::string> kind;
    std::string at;
    for (const auto& in : sc.inputs)
      if (in.name == c.name) kind = io::to_string(in.kind), at = io::to_string(in.at);
    for (const auto& se : sc.sensors)
      if (se.name == c.name) kind = io::to_string(se.kind), at = io::to_string(se.at);
    if (!kind) continue;
    const std::string what = "column '" + io::one_line(c.name) + "'";
    if (!c.quantity.empty() && c.quantity != *kind)
      throw InputError(meta_path + ": " + what + " is a " + c.quantity + " but the scenario's is a " + *kind);
    if (!c.at.empty() && c.at != at)
      throw InputError(meta_path + ": " + what + " is at the " + c.at + " but the scenario's is at the " + at);
    const int col = tab.find(c.name);
    const std::string file_unit = tab.unit(col);
    if (!c.unit.empty() && !file_unit.empty() && file_unit != c.unit)
      throw InputError(meta_path + ": " + what + " is in '" + c.unit + "' but data file '" + csv + "' states '" +
                       file_unit + "'; the two files are not from the same run");
    if (!c.unit.empty()) p.meta_units[c.name] = c.unit;
  }
  for (const auto& c : meta.columns)
    for (std::size_t j = 0; j < sc.sensors.size(); ++j) {
      const auto& s = sc.sensors[j];
      if (s.name != c.name) continue;
      if (p.noise_std[j] <= 0 && c.noise_std > 0) {
        p.noise_std[j] = c.noise_std;
        p.noise_origin[j] = "truth.json";
      }
    }
  return meta.true_parameters;
}

// The record's times on their grid (io/time_grid.h): a stated data.sample_rate's (the times within
// half a step of it), else the uniform grid they round to when their jitter is their written
// precision's. Times already uniform to their arithmetic, or not uniform at all, stay as they are.
void regularise_time(const io::Scenario& sc, io::DataTable& tab, const std::string& source, ColumnUse& use) {
  if (sc.data.sample_rate > 0) {
    std::string why;
    const auto g = io::stated_grid(tab.t, sc.data.sample_rate, &why, tab.stated_step, tab.stated_step_rounding);
    if (!g)
      fail_field(sc.source, "data.sample_rate", "disagrees with the time column '" + tab.time_name + "' of data file '" + source + "': " + why,
                 io::format_value(sc.data.sample_rate));
    use.time = *g;
    use.time_regularised = true;
    tab.t = g->times(tab.t.size());
    return;
  }
  use.time = io::uniform_grid(tab.t);
  if (use.time.uniform && use.time.precision != "full") {
    use.time_regularised = true;
    tab.t = use.time.times(tab.t.size());
  }
}

// data.window: only the samples within [t_start, t_end] are fitted, the model starting at the first
// of them (at rest, or from the state identification.initial_state: estimate finds). The columns
// are read, converted and conditioned whole before (an offset's pre-trigger, a force window's
// noise), and the inputs stay functions of the record's time; a window holding fewer than 3
// samples is refused naming the record's span.
void fit_window(Problem& p, const std::string& source) {
  const auto& w = p.scenario.data.window;
  if (w.size() != 2) return;
  const auto& t = p.data.t;
  std::size_t first = 0, last = t.size();
  while (first < t.size() && t[first] < w[0]) ++first;
  while (last > first && t[last - 1] > w[1]) --last;
  if (last - first < 3)
    fail_field(p.scenario.source, "data.window",
               "holds " + std::to_string(last - first) + " samples of data file '" + source + "' (its times run from " +
                   io::format_value(t.front()) + " to " + io::format_value(t.back()) + " s); at least 3 are needed",
               "[" + io::format_value(w[0]) + ", " + io::format_value(w[1]) + "]");
  if (first == 0 && last == t.size()) return;
  const auto rows = static_cast<Eigen::Index>(last - first);
  p.data.t = std::vector<double>(t.begin() + static_cast<std::ptrdiff_t>(first), t.begin() + static_cast<std::ptrdiff_t>(last));
  p.data.z = MatrixXd(p.data.z.middleRows(static_cast<Eigen::Index>(first), rows));
  p.columns.window = {p.data.t.front(), p.data.t.back()};
}

// Noise levels a lab does not state, from the record's quiet start (docs/data.md §2; the
// estimator io/quiet_start.h). The trigger is the earliest sample at which an input (its column or
// the scenario's signal) exceeds a twentieth of its peak; a sensor without a stated level gets the
// quiet start's σ̂ where it is usable.
void noise_from_quiet_start(Problem& p) {
  const auto& t = p.data.t;
  const std::size_t n = t.size();
  if (n < static_cast<std::size_t>(io::kQuietSamples + io::kQuietMargin) || p.signals.empty()) return;
  std::size_t trigger = n;
  std::vector<double> x(n);
  for (const auto& sig : p.signals) {
    for (std::size_t i = 0; i < n; ++i) x[i] = sig(t[i]);
    trigger = std::min(trigger, io::trigger_sample(x.data(), n));
  }
  const std::size_t quiet = io::quiet_samples(trigger);
  if (trigger >= n || quiet == 0) return;
  bool used = false;
  for (std::size_t j = 0; j < p.noise_std.size(); ++j) {
    if (p.noise_std[j] > 0) continue;
    const double sd = io::quiet_start_noise(p.data.z.col(static_cast<Eigen::Index>(j)).data(), quiet);
    if (!(sd > 0)) continue;
    p.noise_std[j] = sd;
    p.noise_origin[j] = "pre-trigger";
    used = true;
  }
  if (used) {
    p.columns.trigger_time = t[trigger];
    p.columns.quiet_samples = static_cast<int>(quiet);
  }
}

}  // namespace

std::map<std::string, double> read_record(Problem& p, const io::DataTable& table, const std::string& source,
                                          const io::TruthMeta* meta, const std::string& meta_source) {
  io::DataTable tab = table;
  regularise_time(p.scenario, tab, source, p.columns);
  std::map<std::string, double> truth;
  if (meta) truth = apply_truth_meta(p, tab, source, *meta, meta_source);
  measurements_from_table(p, tab, source);
  fit_window(p, source);
  noise_from_quiet_start(p);
  return truth;
}

void check_identifier_step(const io::Scenario& sc, const StructuralModel& model, const Parameterization& params,
                           const std::vector<io::Signal>& signals, const DataContent& content, double h, bool synthetic) {
  const auto& id = sc.identification;
  const double T = sc.simulation.duration;
  const std::string field = id.time_step > 0 ? "identification.time_step" : "identification.elements";
  const std::string got = id.time_step > 0 ? io::format_value(id.time_step)
                                           : std::to_string(id.elements) + " (automatic time step " + io::format_value(h) + ")";
  if (id.time_step > 0 && id.integrator != io::Integrator::Bdf) {
    const double w = content.omega;
    if (w * h > 1.0)
      fail_field(sc.source, "identification.time_step",
                 "must resolve flexible mode " + std::to_string(content.mode) +
                     (id.step_rule == io::StepRule::Data ? std::string(" = the highest the data visibly contain (")
                                             : std::string(" = min(P + 2, modes below Nyquist) (")) +
                     io::format_value(w / (2 * M_PI)) + " Hz at the starting values): omega h = " +
                     io::format_value(w * h) + " > 1; leave it 0 for the automatic step " +
                     io::format_value(std::min(sc.simulation.sample_interval, 0.3 / w)),
                 io::format_value(h));
  }
  // A scenario signal the step cannot resolve would be sampled, not integrated: a pulse shorter than
  // a step is seen whole or not at all (a 1e-9 s pulse of 2e-8 impulse drives a step's worth of
  // response), a sine at or above 1/(2h) aliases into a slow one. (A data column is read on its own
  // grid and is exempt.)
  for (std::size_t i = 0; i < signals.size() && i < sc.inputs.size(); ++i) {
    const io::Signal& s = signals[i];
    const std::string f = "inputs[" + std::to_string(i) + "].signal";
    if (s.shortest_width() < h)
      fail_field(sc.source, f + ".width",
                 "is shorter than the identifier's time step " + io::format_value(h) +
                     " s: a pulse is not resolved by the steps that integrate it (widen it to at least one step, or "
                     "record it faster)",
                 io::format_value(s.shortest_width()));
    if (s.highest_frequency() >= 0.5 / h)
      fail_field(sc.source, f + ".frequency",
                 "is at or above " + io::format_value(0.5 / h) + " Hz, the Nyquist frequency of the identifier's time step " +
                     io::format_value(h) + " s: it would alias into a slower input",
                 io::format_value(s.highest_frequency()));
  }
  const double steps = T / h;
  // State and costate, and the sensitivities in blocks of at most kSensitivityBlockBytes (objective.h).
  const double one = (steps + 1.0) * model.ndof * 3.0 * 8.0;
  const double bytes = 2.0 * one + std::min(params.size() * one, std::max(one, kSensitivityBlockBytes));
  if (!(steps <= io::limits::kMaxSteps) || !(bytes <= io::limits::kMaxTrajectoryBytes))
    fail_field(sc.source, field,
               "gives " + io::format_value(std::ceil(steps)) + " steps of " + std::to_string(model.ndof) + " DOF (about " +
                   io::format_value(std::ceil(bytes / 1048576.0)) + " MiB of trajectories); the limits are " +
                   io::format_value(io::limits::kMaxSteps) + " steps and " +
                   io::format_value(io::limits::kMaxTrajectoryBytes / 1048576.0) + " MiB",
               got);
  if (synthetic) {
    const int de = id.data_elements > 0 ? id.data_elements : 2 * id.elements;
    const double dsteps = 4.0 * steps;
    const double dbytes = (dsteps + 1.0) * model.ndof * (static_cast<double>(de) / id.elements) * 3.0 * 8.0;
    if (!(dsteps <= io::limits::kMaxSteps) || !(dbytes <= io::limits::kMaxTrajectoryBytes))
      fail_field(sc.source, field,
                 "makes the synthetic data (" + std::to_string(de) + " elements, step h/4) take " +
                     io::format_value(std::ceil(dsteps)) + " steps (about " + io::format_value(std::ceil(dbytes / 1048576.0)) +
                     " MiB); the limits are " + io::format_value(io::limits::kMaxSteps) + " steps and " +
                     io::format_value(io::limits::kMaxTrajectoryBytes / 1048576.0) + " MiB",
                 got);
  }
}

void check_record_span(const Problem& p, double h) {
  const double span = p.data.t.back() - p.data.t.front(), steps = h > 0 ? span / h : 0.0;
  if (!(steps <= io::limits::kMaxSteps))
    throw InputError("data file '" + p.data_source + "': column t spans " + io::format_value(span) + " s, " +
                     io::format_value(std::ceil(steps)) + " steps of the identifier's " + io::format_value(h) +
                     " s; the limit is " + io::format_value(io::limits::kMaxSteps) + " steps");
}

void check_band(const Problem& p) {
  const auto& band = p.scenario.identification.band;
  if (band.empty()) return;
  const auto& t = p.data.t;
  const std::string& src = p.scenario.source;
  const double dt = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  if (const io::TimeGrid g = io::uniform_grid(t); !g.uniform) {  // (a coarsely written clock is on its grid by now)
    char buf[320];
    std::snprintf(buf, sizeof buf, "sample %zu at t = %.9g s lies %.3g steps off the uniform grid of %.9g s, more than their writing (%s) explains",
                  g.worst + 1, t[g.worst], g.max_shift / g.step, g.step, g.precision.c_str());
    fail_field(src, "identification.band",
               "needs uniformly sampled data, and the times of '" + p.data_source + "' are not: " + buf +
                   " (a dropped sample, a second segment?); when the DAQ's clock was uniform, state data.sample_rate",
               io::format_value(band[0]) + " .. " + io::format_value(band[1]) + " Hz");
  }
  if (!(band[1] < 0.5 / dt))
    fail_field(src, "identification.band[1]", "must lie below the data's Nyquist frequency " + io::format_value(0.5 / dt) + " Hz",
               io::format_value(band[1]));
  for (std::size_t k = 0; k < p.noise_std.size(); ++k)
    if (!(p.noise_std[k] > 0))
      fail_field(src, "identification.band",
                 "needs every sensor's noise_std stated (the band's noise level and its chi-square band are drawn from it); sensor '" +
                     p.scenario.sensors[k].name + "' has none",
                 io::format_value(band[0]) + " .. " + io::format_value(band[1]) + " Hz");
}

void check_record_levels(const Problem& p, const std::string* csv) {
  if (p.data.z.size() > 0 && (p.data.z.array() == 0.0).all()) {
    if (csv) throw InputError("data file '" + *csv + "': every sensor's column is zero: nothing to identify from");
    fail_field(p.scenario.source, "sensors",
               "record nothing: every sensor's synthetic record is zero (no input within the record, zero amplitudes, or "
               "sensors where the structure cannot move)",
               std::to_string(p.data.sensors()) + " sensor" + (p.data.sensors() == 1 ? "" : "s"));
  }
  // A stated noise level the record contradicts: white noise of std σ added to any signal gives a
  // record whose mean square is at least about σ² (the signal's share adds to it), and over 30 or
  // more samples its sample mean square falls below σ²/9 with probability 3e-10 (χ²₃₀ < 30/9). A level
  // three times the record's RMS is a wrong unit or a typo (noise_std: 1e20), and a fit test drawn
  // from it would pass any start.
  const Eigen::Index N = p.data.z.rows();
  for (Eigen::Index j = 0; j < p.data.z.cols() && N >= 30; ++j) {
    const double sd = p.noise_std[static_cast<std::size_t>(j)];
    const double rms = std::sqrt(p.data.z.col(j).squaredNorm() / static_cast<double>(N));
    if (!(sd > 3.0 * rms)) continue;
    const std::string why = "states more noise than the record holds: sensor '" + p.scenario.sensors[static_cast<std::size_t>(j)].name +
                            "' reads " + io::format_value(rms) + " RMS over " + std::to_string(N) +
                            " samples, and noise of the stated level alone would read about itself";
    if (p.noise_origin[static_cast<std::size_t>(j)] == "truth.json" && csv)
      throw InputError("truth.json beside data file '" + *csv + "': the noise_std of column '" +
                       p.scenario.sensors[static_cast<std::size_t>(j)].name + "' " + why + ", got " + io::format_value(sd));
    fail_field(p.scenario.source, "sensors[" + std::to_string(j) + "].noise_std", why, io::format_value(sd));
  }
  // A synthetic record whose stated noise buries the signal of every sensor: its mean square
  // exceeds the noise's σ² by less than (σ/3)² (over N ≥ 30 samples the noise's own mean square
  // scatters by σ²√(2/N) ≤ 0.26σ², so a signal of a third of σ is the least the record can show).
  // Nothing is determined by such data; every start would "converge" where it is.
  if (!csv && N >= 30) {
    bool signal = false;
    for (Eigen::Index j = 0; j < p.data.z.cols() && !signal; ++j) {
      const double sd = p.noise_std[static_cast<std::size_t>(j)];
      const double ms = p.data.z.col(j).squaredNorm() / static_cast<double>(N);
      signal = !(sd > 0.0) || ms - sd * sd > sd * sd / 9.0;
    }
    if (!signal)
      fail_field(p.scenario.source, "sensors[0].noise_std",
                 "buries every sensor's signal: the synthetic records hold noise of the stated levels and less than a third of "
                 "as much signal, from which no parameter can be determined",
                 io::format_value(p.noise_std.front()));
  }
}

}  // namespace scoleid::identify
