#include "scoleid/identify/run/problem.h"

#include "scoleid/identify/run/frf_run.h"
#include "scoleid/io/uff.h"
#include "scoleid/io/uff_frf.h"

#include "scoleid/identify/door/scenario_door.h"
#include "scoleid/identify/fe/analytic_beam.h"
#include "scoleid/identify/time/checkpoints.h"

#include <stdexcept>
#include <algorithm>
#include <cmath>
#include <complex>
#include <filesystem>
#include <optional>
#include <random>

#include "scoleid/identify/fe/modal.h"
#include "scoleid/identify/inverse/band_filter.h"
#include "scoleid/identify/inverse/spectral_start.h"
#include "scoleid/identify/fe/scole_model.h"
#include "scoleid/identify/time/nonlinear_forward.h"
#include "scoleid/io/error.h"
#include "scoleid/io/quiet_start.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/structure_parameters.h"
#include "scoleid/io/data_source.h"
#include "scoleid/io/units.h"
#include "scoleid/io/validation.h"

namespace scoleid::identify {

using io::fail_field;
using io::InputError;

namespace {

std::vector<io::Signal> scenario_signals(const io::Scenario& sc) {
  std::vector<io::Signal> s;
  for (const auto& in : sc.inputs) s.push_back(in.signal);
  return s;
}

std::vector<double> sample_times(const io::Scenario& sc) {
  std::vector<double> t;
  const double dt = sc.simulation.sample_interval, T = sc.simulation.duration;
  const long n = static_cast<long>(std::floor(T / dt + 1e-9));
  // simulation.record_start: the samples before it are not in the record (the simulation still
  // starts from rest at t = 0).
  const double t_rec = sc.simulation.record_start;
  for (long k = 0; k <= n; ++k)
    if (k * dt >= t_rec - 1e-9 * dt) t.push_back(k * dt);
  if (T - t.back() > 1e-9 * dt) t.push_back(T);
  return t;
}

// The structure's FE model on `elements` elements, with the structure's own sections (not the
// identifier's), and its coefficients at the scenario's values.
std::pair<StructuralModel, VectorXd> true_model(const io::Scenario& sc, int elements) {
  io::Scenario own = sc;
  own.identification.sections = 0;
  const auto st = make_structure(own, elements);
  return {st->model(), st->coefficients(own)};
}

}  // namespace

DataContent data_content(const StructuralModel& model, const Parameterization& params,
                         const std::vector<io::Signal>& signals, double t_end, double sample_interval,
                         bool from_data) {
  VectorXd c;
  MatrixXd dcdq;
  params.coefficients(params.initial(), c, dcdq);
  const AssembledModel ops = assemble(model, c);
  DataContent d;
  d.nyquist = M_PI / sample_interval;
  // K and ω_K from the frequencies alone (modes with ω <= 1e-6 ω_max count as rigid).
  {
    const std::vector<double> w = natural_frequencies(ops.M, ops.K);
    const double wmax = w.empty() ? 0.0 : w.back();
    std::vector<double> below;
    for (double x : w)
      if (x > 1e-6 * wmax && x <= d.nyquist) below.push_back(x);
    d.modes_below_nyquist = static_cast<int>(below.size());
    if (below.empty()) return d;
    d.omega_first = below.front();
    d.mode = std::min(d.modes_below_nyquist, params.size() + 2);
    d.omega = below[static_cast<std::size_t>(d.mode - 1)];
  }
  // The visible content K_data (reported): from the mode shapes.
  const NaturalModes m = natural_modes(ops.M, ops.K);
  std::vector<Eigen::Index> flexible;
  for (Eigen::Index k = 0; k < m.omega.size(); ++k)
    if (m.omega[k] > m.floor && m.omega[k] <= d.nyquist) flexible.push_back(k);
  if (flexible.empty()) return d;
  // The inputs sampled once on a grid fine enough for every frequency up to Nyquist (16 points per
  // sample interval: ω δ <= π/16); F_i(ω) = ∫₀ᵀ f_i(t) e^{−iωt} dt by the midpoint rule.
  const long n = std::max(16L, static_cast<long>(std::ceil(16.0 * t_end / sample_interval)));
  const double delta = t_end / static_cast<double>(n);
  std::vector<std::vector<double>> f(signals.size(), std::vector<double>(static_cast<std::size_t>(n)));
  for (std::size_t i = 0; i < signals.size(); ++i)
    for (long q = 0; q < n; ++q) f[i][static_cast<std::size_t>(q)] = signals[i]((q + 0.5) * delta);
  const MatrixXd C0 = model.output_matrix(0), C1 = model.output_matrix(1), C2 = model.output_matrix(2);
  const Eigen::Index ns = C0.rows();
  MatrixXd A(ns, static_cast<Eigen::Index>(flexible.size()));
  for (std::size_t a = 0; a < flexible.size(); ++a) {
    const Eigen::Index k = flexible[a];
    const double w = m.omega[k];
    const VectorXd phi = m.vectors.col(k);
    // Modal excitation |Σ_i (φᵀ b_i) F_i(ω_k)|; the undamped modal response to it has amplitude at
    // most that over ω_k.
    std::complex<double> excitation = 0.0;
    const std::complex<double> rot = std::polar(1.0, -w * delta);
    for (std::size_t i = 0; i < signals.size(); ++i) {
      std::complex<double> e = std::polar(1.0, -w * 0.5 * delta), F = 0.0;
      for (long q = 0; q < n; ++q) {
        F += f[i][static_cast<std::size_t>(q)] * e;
        e *= rot;
      }
      excitation += phi.dot(ops.loads[i]) * F * delta;
    }
    const VectorXd g = C0 * phi;
    const VectorXd g1 = C1.rows() == ns ? VectorXd(C1 * phi) : VectorXd::Zero(ns);
    const VectorXd g2 = C2.rows() == ns ? VectorXd(C2 * phi) : VectorXd::Zero(ns);
    for (Eigen::Index j = 0; j < ns; ++j)
      A(j, static_cast<Eigen::Index>(a)) =
          (std::abs(g[j]) + w * std::abs(g1[j]) + w * w * std::abs(g2[j])) * std::abs(excitation) / w;
  }
  int last = -1;
  for (Eigen::Index j = 0; j < ns; ++j) {
    const double top = A.row(j).maxCoeff();
    if (!(top > 0)) continue;
    for (Eigen::Index a = A.cols() - 1; a > last; --a)
      if (A(j, a) >= kModeContentThreshold * top) {
        last = static_cast<int>(a);
        break;
      }
  }
  d.content_mode = last + 1;
  if (from_data && d.content_mode > 0) {  // the step from the visible content, whatever P
    d.mode = d.content_mode;
    d.omega = m.omega[flexible[static_cast<std::size_t>(d.mode - 1)]];
  }
  // The step resolves K = min(P + 2, K_nyq), not K_data: a mode far below the largest in amplitude
  // can still be the one that carries a weakly seen parameter (SCOLE's modes 5 and 6, at < 1e-4 of
  // the first in every sensor, fix ρI_ψ to 4e-5 when resolved and leave it 5e-3 off when not).
  return d;
}

double numerical_damping_ratio(const ButcherTable& t, double x) {
  // One step of y' = i ω y multiplies y by R(z) = 1 + z bᵀ (I − zA)⁻¹ 1 at z = i x; the
  // amplitude decays as exp(−ζ ω h) per step.
  const int s = t.stages;
  const std::complex<double> z(0.0, x);
  Eigen::MatrixXcd IA = Eigen::MatrixXcd::Identity(s, s);
  for (int i = 0; i < s; ++i)
    for (int j = 0; j < s; ++j) IA(i, j) -= z * t.a(i, j);
  const Eigen::VectorXcd k = IA.partialPivLu().solve(Eigen::VectorXcd::Ones(s));
  std::complex<double> R = 1.0;
  for (int i = 0; i < s; ++i) R += z * t.b[static_cast<std::size_t>(i)] * k[i];
  return -std::log(std::abs(R)) / x;
}

namespace {
// Whether a parameter moves a coefficient of the damping operator (at the starting values).
bool estimates_damping(const StructuralModel& model, const Parameterization& params) {
  VectorXd c;
  MatrixXd dcdq;
  params.coefficients(params.initial(), c, dcdq);
  for (const auto& term : model.damping)
    if (term.coefficient >= 0 && dcdq.row(term.coefficient).cwiseAbs().maxCoeff() > 0.0) return true;
  return false;
}

// The smallest positive modal damping ratio φᵀDφ / (2ω) (M-orthonormal φ) over the flexible
// modes 1 … count at the starting parameters; 0 if none is damped.
double smallest_modal_damping(const StructuralModel& model, const Parameterization& params, int count) {
  VectorXd c;
  MatrixXd dcdq;
  params.coefficients(params.initial(), c, dcdq);
  const AssembledModel ops = assemble(model, c);
  const NaturalModes m = natural_modes(ops.M, ops.K);
  const MatrixXd D(ops.D);
  double smallest = 0.0;
  int counted = 0;
  for (Eigen::Index k = 0; k < m.omega.size() && counted < count; ++k) {
    if (!(m.omega[k] > m.floor)) continue;
    ++counted;
    const VectorXd phi = m.vectors.col(k);
    const double z = phi.dot(D * phi) / (2.0 * m.omega[k]);
    if (z > 0.0 && (smallest == 0.0 || z < smallest)) smallest = z;
  }
  return smallest;
}
}  // namespace

namespace {
// The longest step at most h0 whose numerical damping ratio at frequency w is at most target
// (ζ_num grows with x = ω h on (0, 0.3]).
double damping_bounded_step(const ButcherTable& table, double w, double h0, double target) {
  if (!(numerical_damping_ratio(table, w * h0) > target)) return h0;
  double lo = 0.0, hi = w * h0;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (numerical_damping_ratio(table, mid) > target ? hi : lo) = mid;
  }
  return lo / w;
}

int implicit_stages(const ButcherTable& t) {
  int k = 0;
  for (int i = 0; i < t.stages; ++i) k += t.a(i, i) != 0.0;
  return k;
}
}  // namespace

IdentifierStep identifier_integration(const io::Scenario& sc, const StructuralModel& model, const Parameterization& params,
                                      const std::vector<io::Signal>& signals) {
  if (sc.identification.time_step > 0) return {sc.identification.time_step, -1, sc.identification.time_step};
  // Resolve (ω h <= 0.3) modes 1 … K, K = min(P + 2, modes below Nyquist) (data_content): an
  // L-stable step damps what it does not resolve, keeping its quasi-static part.
  const DataContent content = data_content(model, params, signals, sc.simulation.duration, sc.simulation.sample_interval,
                                           sc.identification.step_rule == io::StepRule::Data);
  const double w = content.omega;
  double h = sc.simulation.sample_interval;
  if (w > 0) h = std::min(h, 0.3 / w);
  // A damping parameter is read from decay rates: the step's own damping in that band must be
  // small against the physical one, ζ_num(ω_K h) <= 1 % of the smallest modal damping ratio
  // there (docs/theory.md §5.2), or the fit absorbs the integrator's damping into the estimate.
  IdentifierStep out{h, -1, h};
  if (w > 0 && estimates_damping(model, params)) {
    const double target = 0.01 * smallest_modal_damping(model, params, content.mode);
    if (target > 0.0) {
      const ButcherTable third = ButcherTable::arkode_dirk(-1), fourth = ButcherTable::arkode_dirk(ButcherTable::esdirk436_id());
      const double h3 = damping_bounded_step(third, w, h, target), h4 = damping_bounded_step(fourth, w, h, target);
      out = {h3, -1, h3};
      // (The nonlinear model steps with its own third-order table, nonlinear_forward.h.)
      const bool linear = sc.identification.model != io::Model::Nonlinear;
      if (linear && h3 < h && implicit_stages(fourth) / h4 < implicit_stages(third) / h3)
        out = {h4, ButcherTable::esdirk436_id(), h3};
    }
  }
  return out;
}

double identifier_step(const io::Scenario& sc, const StructuralModel& model, const Parameterization& params,
                       const std::vector<io::Signal>& signals) {
  return identifier_integration(sc, model, params, signals).step;
}

namespace {
// Refuses a step the run cannot afford or cannot trust, before any solve: a step given in the
// scenario that does not resolve the modes the data contain (ω_K h > 1: the L-stable step would
// damp them away and the fit would absorb that into the parameters), and trajectory storage
// beyond io::limits (state, costate and, for Gauss–Newton or the standard deviations, a block of
// sensitivity trajectories; synthetic data on its finer mesh and step).
void check_step(const io::Scenario& sc, const StructuralModel& model, const Parameterization& params,
                const std::vector<io::Signal>& signals, double h, bool synthetic) {
  const auto& id = sc.identification;
  const double T = sc.simulation.duration;
  const std::string field = id.time_step > 0 ? "identification.time_step" : "identification.elements";
  const std::string got = id.time_step > 0 ? io::format_value(id.time_step)
                                           : std::to_string(id.elements) + " (automatic time step " + io::format_value(h) + ")";
  if (id.time_step > 0 && id.integrator != "bdf") {
    const DataContent content = data_content(model, params, signals, sc.simulation.duration, sc.simulation.sample_interval,
                                             id.step_rule == io::StepRule::Data);
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
}  // namespace

namespace {
// Names, the truth's sensor errors (truth.overrides.sensors: bias and drift, as the Simbody truth
// adds them) and, if asked, each sensor's seeded Gaussian noise.
void add_sensor_errors(const io::Scenario& sc, bool add_noise, Measurements& m) {
  for (const auto& s : sc.sensors) m.names.push_back(s.name);
  for (std::size_t j = 0; j < sc.sensors.size(); ++j)
    for (Eigen::Index k = 0; k < m.z.rows(); ++k)
      m.z(k, static_cast<Eigen::Index>(j)) += sc.sensors[j].bias + sc.sensors[j].drift * m.t[static_cast<std::size_t>(k)];
  if (add_noise) {
    std::mt19937_64 rng(sc.simulation.seed);
    for (std::size_t j = 0; j < sc.sensors.size(); ++j) {
      const double sd = sc.sensors[j].noise_std;
      if (sd <= 0) continue;
      std::normal_distribution<double> N(0.0, sd);
      for (Eigen::Index k = 0; k < m.z.rows(); ++k) m.z(k, static_cast<Eigen::Index>(j)) += N(rng);
    }
  }
}
}  // namespace

io::DataTable measurement_table(const io::Scenario& sc, const Measurements& m) {
  io::DataTable table;
  table.t = m.t;
  for (const auto& in : sc.inputs) {
    table.names.push_back(in.name);
    table.columns.emplace_back();
    for (double t : m.t) table.columns.back().push_back(in.signal(t));
  }
  for (std::size_t j = 0; j < m.names.size(); ++j) {
    table.names.push_back(m.names[j]);
    table.columns.emplace_back(m.t.size());
    for (std::size_t k = 0; k < m.t.size(); ++k)
      table.columns.back()[k] = m.z(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j));
  }
  return table;
}

Measurements synthesize_series(const io::Scenario& sc, int terms) {
  Measurements m;
  m.names = {sc.sensors.empty() ? std::string() : sc.sensors[0].name};
  const std::vector<double> w = analytic::ss_scenario_samples(sc, terms);
  m.z = Eigen::Map<const Eigen::VectorXd>(w.data(), static_cast<Eigen::Index>(w.size()));
  for (std::size_t k = 0; k < w.size(); ++k) m.t.push_back(static_cast<double>(k) * sc.simulation.sample_interval);
  return m;
}

Measurements synthesize(const io::Scenario& sc, int elements, double rtol, double step, bool add_noise, int dirk_table) {
  const auto [model, coefficients] = true_model(sc, elements);
  const AssembledModel ops = assemble(model, coefficients);
  SolverOptions so;
  so.rtol = rtol;
  so.step = step;
  so.dirk_table = dirk_table;
  SecondOrderSolver solver(ops.M, ops.D, ops.K, model.dof_group, so);
  const auto signals = scenario_signals(sc);
  const int n = model.ndof;
  SecondOrderSolver::Forcing f = [&](double t, double* F) {
    Eigen::Map<VectorXd> Fm(F, n);
    for (std::size_t i = 0; i < signals.size(); ++i) Fm += signals[i](t) * ops.loads[i];
  };
  std::vector<double> bps;
  for (const auto& s : signals)
    for (double b : s.breakpoints()) bps.push_back(b);
  const auto times = sample_times(sc);
  Measurements m;
  m.t = times;
  // y = C_0 u + C_1 u̇ + C_2 ü, ü from the equation of motion at the sample time; streamed, so only
  // the samples are kept (the finer mesh at the finer step would otherwise be the run's largest array).
  const MatrixXd C = model.output_matrix(0), C1 = model.output_matrix(1), C2 = model.output_matrix(2);
  const bool rates = model.has_rate_outputs();
  m.z.resize(static_cast<Eigen::Index>(times.size()), C.rows());
  VectorXd a(n), F(n);
  sample_streamed(solver, 0.0, times.back(), f, bps, times, [&](std::size_t k, const VectorXd& x, const VectorXd& v) {
    VectorXd y = C * x;
    if (rates) {
      F.setZero();
      f(times[k], F.data());
      solver.acceleration(F.data(), x.data(), v.data(), a.data());
      y += C1 * v + C2 * a;
    }
    m.z.row(static_cast<Eigen::Index>(k)) = y.transpose();
  });
  add_sensor_errors(sc, add_noise, m);
  return m;
}

Measurements synthesize_nonlinear(const io::Scenario& sc, int elements, double step, bool add_noise) {
  const auto [model, coefficients] = true_model(sc, elements);
  const ScoleNonlinear nl = scole_nonlinear(sc, elements);
  NonlinearForwardOptions o;
  o.max_step = step;
  if (sc.simulation.record_start > 0)  // refused by the door (check_synthesis)
    throw std::logic_error("synthesize_nonlinear: simulation.record_start " + io::format_value(sc.simulation.record_start));
  Measurements m;
  m.t = sample_times(sc);
  m.z = simulate_nonlinear(nl.at(coefficients), scenario_signals(sc), m.t, o).outputs;
  add_sensor_errors(sc, add_noise, m);
  return m;
}

namespace {

// The true values of the estimated parameters for a structure (the truth's), translated to the
// problem's parameterization.
void set_true_values(Problem& p, const io::Scenario& truth_sc) {
  // The truth's values need not be valid starting values (an absent damper of the truth is 0):
  // only truth() is read.
  const VectorXd tv = PhysicalParameterization(p.structure->parameter_space(truth_sc), truth_sc.identification).truth();
  for (int i = 0; i < tv.size(); ++i)
    if (std::isfinite(tv[i])) p.true_values[p.params->names()[static_cast<std::size_t>(i)]] = tv[i];
}

// The structure, its parameters, the scenario's signals and the stated noise levels.
std::unique_ptr<Problem> problem_skeleton(const io::Scenario& sc) {
  check_scenario(sc);
  auto p = std::make_unique<Problem>();
  p->scenario = sc;
  p->structure = make_structure(sc, sc.identification.elements);
  check_parameters(*p->structure, sc);
  p->params = p->structure->parameterize(sc);
  p->signals = scenario_signals(sc);
  p->noise_std.assign(sc.sensors.size(), 0.0);
  p->noise_origin.assign(sc.sensors.size(), "");
  for (std::size_t j = 0; j < sc.sensors.size(); ++j)
    if (sc.sensors[j].noise_std > 0) {
      p->noise_std[j] = sc.sensors[j].noise_std;
      p->noise_origin[j] = "scenario";
    }
  return p;
}

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
  ColumnUse::SteppedInput st{in.name, 0.0, 0.0, 0.0, !in.signal.terms().empty()};
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

// Synthetic data: the truth's structure (truth.overrides applied) on a finer mesh, with a step 4x
// finer than the identifier's. Returns the identifier's step.
IdentifierStep synthesize_data(Problem& p) {
  const auto& sc = p.scenario;
  const auto& id = sc.identification;
  const int data_elements = id.data_elements > 0 ? id.data_elements : 2 * id.elements;
  const IdentifierStep is = identifier_integration(sc, p.model(), *p.params, p.signals);
  const double step = is.step;
  check_step(sc, p.model(), *p.params, p.signals, step, true);
  p.content = data_content(p.model(), *p.params, p.signals, sc.simulation.duration, sc.simulation.sample_interval,
                           id.step_rule == io::StepRule::Data);
  const io::Scenario truth_sc = io::truth_scenario(sc);
  io::check_fe_reproduces_truth(sc.source, truth_sc,
                                 "the finite-element synthesis cannot produce it (generate the data with scole-truth "
                                 "and pass them with --data)");
  p.data = id.model == io::Model::Nonlinear ? synthesize_nonlinear(truth_sc, data_elements, step / 4.0, true)
                                            : synthesize(truth_sc, data_elements, id.rtol, step / 4.0, true, is.dirk_table);
  p.data_source = "synthetic (" + std::to_string(data_elements) + " elements)";
  set_true_values(p, truth_sc);
  return is;
}

// The identifier's step for measured data (the inputs as they will drive the model: a data column
// replaces a scenario signal), within the limits for the record's own span.
IdentifierStep measured_data_step(Problem& p, const std::string& csv) {
  const auto& sc = p.scenario;
  const IdentifierStep is = identifier_integration(sc, p.model(), *p.params, p.signals);
  const double step = is.step;
  check_step(sc, p.model(), *p.params, p.signals, step, false);
  const double span = p.data.t.back() - p.data.t.front(), steps = step > 0 ? span / step : 0.0;
  if (!(steps <= io::limits::kMaxSteps))
    throw InputError("data file '" + csv + "': column t spans " + io::format_value(span) + " s, " +
                     io::format_value(std::ceil(steps)) + " steps of the identifier's " + io::format_value(step) +
                     " s; the limit is " + io::format_value(io::limits::kMaxSteps) + " steps");
  p.content = data_content(p.model(), *p.params, p.signals, sc.simulation.duration, sc.simulation.sample_interval,
                           sc.identification.step_rule == io::StepRule::Data);
  return is;
}

// identification.band (inverse/band_filter.h): the inputs' samples at the data's times and the
// data filtered alike; the stated noise levels become the filtered data's.
void apply_band(Problem& p) {
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
  const BandFilter g(band[0], band[1], dt);
  for (auto& sig : p.signals) {
    std::vector<double> f(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) f[i] = sig(t[i]);
    sig = io::Signal::cubic_table(t, g.apply(f));
  }
  std::vector<double> col(t.size());
  for (Eigen::Index k = 0; k < p.data.z.cols(); ++k) {
    for (std::size_t i = 0; i < t.size(); ++i) col[i] = p.data.z(static_cast<Eigen::Index>(i), k);
    const auto y = g.apply(col);
    for (std::size_t i = 0; i < t.size(); ++i) p.data.z(static_cast<Eigen::Index>(i), k) = y[i];
  }
  p.band_gain = g.noise_gain(t.size());
  for (double& sd : p.noise_std) sd *= std::sqrt(p.band_gain);
}

// identification.band: auto on a measured record (docs/data.md §2.4). The band's top stays where
// the model can follow what it is given: an input read from a data column reaches the model,
// once band-filtered, through the 4-point Lagrange cubic through its samples (io::Signal's
// cubic-table), whose reading of a sinusoid of x = f·Δt cycles per sample is wrong by E(x)
// (io::cubic_table_error, relative RMS: its gain's share and the images at multiples of the
// sample rate ± f, which the model's high modes answer and its sampled outputs fold back onto f):
// 0.25 % at x = 0.0996, 0.5 % at 0.119, 6.2 % at 0.23. A 2 kHz steel-strip record fitted with its
// fourth mode at x = 0.117 gave EI and ρA 1.5 % low; sampled at 4 kHz (x = 0.058), 0.15 %. Peaks
// are kept where E is at most a quarter of the declared model error a (1 % unless stated), and the
// top edge stays where it is at most half; without such an input both limits are 0.45/Δt, under
// the Nyquist frequency. Below the limit the record's spectral peaks (spectral_start.h, at least
// 10⁻³ of the strongest) are kept; the top edge lies midway (in log frequency) between the
// highest peak kept and the next one above, if any, and at least 10 % above the peak kept (else
// that peak is dropped, a skirt that cuts a mode being worse than one without it); the bottom
// edge at half the lowest peak or half the model's first mode at the start, whichever is lower
// (an offset, a drift and a transducer's low-frequency noise stay out; a record too short to show
// its first mode as a peak still holds it). No band when no peak lies below the limit, a sensor has no noise level, the times are not
// uniform, or a data input steps within a sample (not an impact) or at the record's first sample:
// the run says which.
// The x = f·Δt below which io::cubic_table_error stays within `error` (it grows monotonically up to 0.45).
double lagrange_limit(double error) {
  double lo = 0.0, hi = 0.45;
  if (io::cubic_table_error(hi) <= error) return hi;
  for (int it = 0; it < 60; ++it) (io::cubic_table_error(0.5 * (lo + hi)) > error ? hi : lo) = 0.5 * (lo + hi);
  return lo;
}

void choose_band(Problem& p) {
  auto& id = p.scenario.identification;
  if (!p.measured || !id.band.empty() || id.band_mode != io::IdentificationSpec::BandMode::Auto || id.model != io::Model::Linear) return;
  const auto& t = p.data.t;
  auto hz = [](double f) {
    char b[32];
    std::snprintf(b, sizeof b, "%.4g", f);
    return std::string(b);
  };
  auto none = [&](const std::string& why) { p.band_note = "auto: the whole record (" + why + ")"; };
  if (id.initial_state == io::InitialState::Estimate)
    return none("the initial state is estimated, and a band's filter commutes with the model only from rest");
  if (t.size() < 64) return none("fewer than 64 samples");
  for (std::size_t k = 0; k < p.noise_std.size(); ++k)
    if (!(p.noise_std[k] > 0)) return none("sensor '" + p.scenario.sensors[k].name + "' has no noise level; a band needs every sensor's");
  if (!io::uniform_grid(t).uniform) return none("the times are not uniform");
  // A data input that steps within a sample (not an impact): the band's filter would turn its
  // jump into a band-limited edge the cubic reading rings on, where the linear reading keeps it
  // within its sample.
  for (const auto& st : p.columns.stepped_inputs)
    if (st.pulse_samples == 0) return none("input '" + st.name + "' steps within a sample");
  // (the same for an input that is not at rest at the record's first sample: it jumps there from
  // the rest the model starts at)
  for (std::size_t i = 0; i < p.scenario.inputs.size() && i < p.signals.size(); ++i) {
    const auto& from_data = p.columns.inputs_from_data;
    if (std::find(from_data.begin(), from_data.end(), p.scenario.inputs[i].name) == from_data.end()) continue;
    double peak = 0.0;
    for (double ti : t) peak = std::max(peak, std::abs(p.signals[i](ti)));
    if (std::abs(p.signals[i](t.front())) > 0.05 * peak)
      return none("input '" + p.scenario.inputs[i].name + "' is not at rest at the record's first sample: it steps there from the model's rest");
  }
  const double dt = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  const double allowance = id.model_error > 0 ? id.model_error : 0.01;
  const bool data_input = !p.columns.inputs_from_data.empty();
  const double f_peaks = (data_input ? lagrange_limit(0.25 * allowance) : 0.45) / dt;
  const double f_limit = (data_input ? lagrange_limit(0.5 * allowance) : 0.45) / dt;
  std::vector<SpectralPeak> peaks = spectral_peaks(t, p.data.z, 12);
  std::sort(peaks.begin(), peaks.end(), [](const SpectralPeak& a, const SpectralPeak& b) { return a.f < b.f; });
  std::vector<double> kept;
  double above = 0.0;
  for (const auto& pk : peaks) {
    if (pk.f < f_peaks) kept.push_back(pk.f);
    else if (above == 0.0) above = pk.f;
  }
  double f_hi = 0.0;
  while (!kept.empty()) {
    f_hi = above > 0 ? std::min(f_limit, std::sqrt(kept.back() * above)) : f_limit;
    if (f_hi >= 1.1 * kept.back()) break;
    above = kept.back();
    kept.pop_back();
  }
  const std::string limit = !data_input ? hz(f_limit) + " Hz (0.45 of the sample rate)"
                                        : hz(f_limit) + " Hz, peaks below " + hz(f_peaks) +
                                              " Hz (where the data input's cubic reading between samples is wrong by half the model error, " +
                                              hz(50 * allowance) + " %, and by a quarter)";
  if (kept.empty()) return none("no spectral peak below " + hz(f_peaks) + " Hz");
  // (the bottom edge also under half the model's first mode at the start: a record too short to
  // show that mode as a peak still holds it)
  const double f_first = p.content.omega_first / (2.0 * M_PI);
  id.band = {f_first > 0 ? 0.5 * std::min(kept.front(), f_first) : 0.5 * kept.front(), f_hi};
  std::string list;
  for (double f : kept) list += (list.empty() ? "" : ", ") + hz(f);
  p.band_note = "auto: [" + hz(id.band[0]) + ", " + hz(id.band[1]) + "] Hz around the record's peaks at " +
                list + " Hz" + (above > 0 ? "; the next, " + hz(above) + " Hz, left out" : std::string()) +
                "; the top at most " + limit;
}

// An input read from the data that oscillates (20 or more crossings of its mean) about a level
// that is not zero (95 % of its samples on that level's side of zero) carries a static offset the
// model would take as a force — a shaker's load cell reads a force that reverses; a step or a slew
// crosses its mean a few times and is left alone (docs/data.md §2.5): a warning naming it and the
// conditioning that removes it. Read before the band, whose high-pass would hide it.
void input_offsets(Problem& p) {
  const auto& t = p.data.t;
  if (!p.measured || t.size() < 4) return;
  const auto& from_data = p.columns.inputs_from_data;
  for (std::size_t i = 0; i < p.scenario.inputs.size() && i < p.signals.size(); ++i) {
    const auto& in = p.scenario.inputs[i];
    if (std::find(from_data.begin(), from_data.end(), in.name) == from_data.end()) continue;
    std::vector<double> x(t.size());
    double mean = 0.0, ms = 0.0;
    for (std::size_t k = 0; k < t.size(); ++k) mean += (x[k] = p.signals[i](t[k])) / static_cast<double>(t.size());
    for (double v : x) ms += (v - mean) * (v - mean) / static_cast<double>(t.size());
    std::size_t crossings = 0, same_side = 0;
    for (std::size_t k = 0; k < x.size(); ++k) {
      if (k > 0 && (x[k] - mean) * (x[k - 1] - mean) < 0) ++crossings;
      if (x[k] * mean > 0) ++same_side;
    }
    if (crossings < 20 || !(static_cast<double>(same_side) >= 0.95 * static_cast<double>(x.size())) || !(ms > 0)) continue;
    char b[160];
    std::snprintf(b, sizeof b, "input '%s' has a mean of %.3g %s (%.3g times its RMS about the mean)", in.name.c_str(), mean, in.unit.c_str(),
                  std::abs(mean) / std::sqrt(ms));
    p.warnings.push_back(std::string(b) +
                         ": a transducer's static offset, which the model takes as force? conditioning: {offset: mean} (or "
                         "{offset: {mean_before: T}}) on it removes it");
    p.static_offsets.emplace_back(i, mean);
  }
}

// A record that starts moving (docs/theory.md §6.9): before any input acts, a sensor's samples
// scatter by more than five times its stated noise and a twentieth of its record's RMS. The model
// starts from rest, so the first part of such a record is a response it cannot make; the warning
// names the sensor and initial_state: estimate.
void moving_start(Problem& p) {
  if (p.scenario.identification.initial_state != io::InitialState::Rest) return;
  const auto& t = p.data.t;
  const std::size_t N = t.size();
  std::size_t quiet = std::max<std::size_t>(8, N / 100);
  for (std::size_t i = 0; i < p.signals.size(); ++i) {
    double peak = 0.0;
    for (double ti : t) peak = std::max(peak, std::abs(p.signals[i](ti)));
    if (!(peak > 0)) continue;
    for (std::size_t k = 0; k < quiet && k < N; ++k)
      if (std::abs(p.signals[i](t[k])) > 0.05 * peak) quiet = k;
  }
  if (quiet < 4 || quiet > N) return;
  for (Eigen::Index j = 0; j < p.data.z.cols(); ++j) {
    const auto col = p.data.z.col(j);
    const double mean = col.head(static_cast<Eigen::Index>(quiet)).mean();
    const double sd = std::sqrt((col.head(static_cast<Eigen::Index>(quiet)).array() - mean).square().mean());
    const double rms = std::sqrt(col.squaredNorm() / static_cast<double>(N));
    const double noise = static_cast<std::size_t>(j) < p.noise_std.size() ? p.noise_std[static_cast<std::size_t>(j)] : 0.0;
    if (!(sd > 5.0 * noise && sd > 0.05 * rms)) continue;
    char b[200];
    std::snprintf(b, sizeof b, "sensor '%s' is moving at the record's start: its first %zu samples, before any input acts, scatter by %.3g %s (%.2g of its RMS)",
                  p.scenario.sensors[static_cast<std::size_t>(j)].name.c_str(), quiet, sd,
                  p.scenario.sensors[static_cast<std::size_t>(j)].unit.c_str(), sd / rms);
    p.warnings.push_back(std::string(b) +
                         "; the model starts from rest, and identification.initial_state: estimate fits the state the record "
                         "starts in");
    return;
  }
}

// The solver's options, once the data are in: a record in which no sensor moves is refused (every
// parameter fits it the same until the model moves, and then only worse).
void finish_problem(Problem& p, const IdentifierStep& step, const std::string* csv) {
  const auto& id = p.scenario.identification;
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
  input_offsets(p);
  if (id.domain == io::Domain::Frequency) {  // FRFs of the record, no time-domain model (frf_run.h)
    frf_from_record(p);
    return;
  }
  moving_start(p);
  choose_band(p);
  apply_band(p);
  p.objective_options.solver.rtol = id.rtol;
  p.objective_options.solver.step = step.step;
  p.objective_options.solver.dirk_table = step.dirk_table;
  p.objective_options.noise_std = p.noise_std;
  p.objective_options.noise_independent_fraction = p.band_gain;
  p.objective_options.solver.integrator = id.integrator == "bdf"             ? SolverOptions::Integrator::Bdf
                                          : id.integrator == "esdirk-arkode" ? SolverOptions::Integrator::EsdirkArkode
                                                                             : SolverOptions::Integrator::Esdirk;
  if (id.initial_state == io::InitialState::Estimate) {  // esdirk, not Krylov (the door: check_scenario)
    // The flexible modes the step resolves (the data's content, docs/theory.md §5.2), or as stated.
    p.objective_options.initial_state_modes =
        id.initial_state_modes > 0 ? id.initial_state_modes
                                   : std::clamp(p.content.mode, 1, io::kMaxInitialStateModes);
  }
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

// The problem from measured data: the table's columns, the metadata beside it.
std::unique_ptr<Problem> from_table(std::unique_ptr<Problem> p, const io::DataTable& table, const std::string& source,
                                    const io::TruthMeta* meta, const std::string& meta_source) {
  p->measured = true;
  io::DataTable tab = table;
  regularise_time(p->scenario, tab, source, p->columns);
  std::map<std::string, double> meta_truth;
  if (meta) meta_truth = apply_truth_meta(*p, tab, source, *meta, meta_source);
  measurements_from_table(*p, tab, source);
  fit_window(*p, source);
  noise_from_quiet_start(*p);
  if (!meta_truth.empty()) {
    io::Scenario truth_sc = p->scenario;
    io::set_structure_parameters(truth_sc, meta_truth);
    set_true_values(*p, truth_sc);
  }
  const bool frequency = p->scenario.identification.domain == io::Domain::Frequency;
  finish_problem(*p, frequency ? IdentifierStep{} : measured_data_step(*p, source), &source);
  return p;
}

}  // namespace

std::unique_ptr<Problem> make_problem(const io::Scenario& sc, const io::DataTable& table, const std::string& source,
                                      const io::TruthMeta* meta, const std::string& meta_source) {
  return from_table(problem_skeleton(sc), table, source, meta, meta_source);
}

std::unique_ptr<Problem> make_problem(const io::Scenario& sc, const std::optional<std::string>& data_csv) {
  auto p = problem_skeleton(sc);
  if (!data_csv) {
    check_synthesis(sc);
    finish_problem(*p, synthesize_data(*p), nullptr);
    return p;
  }
  if (sc.identification.domain == io::Domain::Frequency && io::is_uff_file(*data_csv)) {
    const io::uff::File file = io::uff::read_file(*data_csv);
    if (std::any_of(file.functions.begin(), file.functions.end(), [](const io::uff::Function& f) { return f.function_type == 4; })) {
      io::UffFrfOptions o;
      o.stations = sc.identification.frf.stations;
      o.reference = sc.identification.frf.reference;
      o.relative_std = sc.identification.frf.relative_std;
      o.averages = sc.identification.frf.averages;
      o.source = sc.source;
      std::vector<int> orders;
      io::FrfData d = io::frf_data_from_uff(file, *data_csv, o, &orders);
      p->measured = true;
      p->data_source = *data_csv;
      p->data.names.clear();
      for (const auto& s : sc.sensors) p->data.names.push_back(s.name);
      frf_from_file(*p, std::move(d), orders);
      return p;
    }
  }
  const io::DataTable tab = io::read_data(*data_csv, {sc.data.time_column, sc.data.time_unit});
  // Truth metadata beside the CSV, when present, supplies the true values and the noise levels.
  const auto meta_path = std::filesystem::path(*data_csv).parent_path() / "truth.json";
  if (!std::filesystem::exists(meta_path)) return from_table(std::move(p), tab, *data_csv, nullptr, "");
  const io::TruthMeta meta = io::read_truth_meta(meta_path.string());
  return from_table(std::move(p), tab, *data_csv, &meta, meta_path.string());
}

}  // namespace scoleid::identify
