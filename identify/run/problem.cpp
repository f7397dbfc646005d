#include "scoleid/identify/run/problem.h"

#include "scoleid/identify/door/frf_door.h"
#include "scoleid/io/uff.h"
#include "scoleid/io/uff_frf.h"

#include "scoleid/identify/door/record_door.h"
#include "scoleid/identify/door/scenario_door.h"
#include "scoleid/identify/fe/analytic_beam.h"
#include "scoleid/identify/time/checkpoints.h"

#include <stdexcept>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <filesystem>
#include <optional>
#include <random>

#include "scoleid/identify/fe/lowest_modes.h"
#include "scoleid/identify/fe/modal.h"
#include "scoleid/identify/inverse/band_filter.h"
#include "scoleid/identify/inverse/spectral_start.h"
#include "scoleid/identify/fe/scole_model.h"
#include "scoleid/identify/time/nonlinear_forward.h"
#include "scoleid/io/error.h"
#include "scoleid/io/progress.h"
#include "scoleid/io/structure_parameters.h"
#include "scoleid/io/data_source.h"
#include "scoleid/io/validation.h"

namespace scoleid::identify {


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

StartModes::StartModes(const StructuralModel& model, const Parameterization& params, bool verbose)
    : model_(model), params_(params), verbose_(verbose) {
  VectorXd c;
  MatrixXd dcdq;
  params.coefficients(params.initial(), c, dcdq);
  ops_ = assemble(model, c);
}

bool StartModes::sparse(double up_to) {
  if (model_.ndof < kSparseModesFrom || !(up_to > 0)) return false;
  if (!below_count_ || counted_at_ != up_to) {
    below_count_ = modes_below(ops_.M, ops_.K, up_to);
    counted_at_ = up_to;
  }
  return *below_count_ >= 0 && sparse_modes_pay(model_.ndof, *below_count_) && !sparse_failed_;
}

const std::vector<double>& StartModes::frequencies(double up_to) {
  if (sparse(up_to)) {
    const NaturalModes& m = modes(up_to);
    if (!sparse_failed_) {
      frequencies_ = std::vector<double>(m.omega.data(), m.omega.data() + m.omega.size());
      frequencies_all_ = false;
      return *frequencies_;
    }
  }
  if (!frequencies_all_) {
    if (verbose_ && model_.ndof >= kSparseModesFrom)
      io::progress("the starting model's frequencies: a dense eigen-solution of %d degrees of freedom, about %.2g s (O(n^3); fewer "
                   "elements are faster)\n",
                   model_.ndof, dense_eigen_seconds(model_.ndof, false));
    frequencies_ = natural_frequencies(ops_.M, ops_.K);
    frequencies_all_ = true;
    rigid_below_ = rigid_floor(ops_.M, ops_.K);
  }
  return *frequencies_;
}

const NaturalModes& StartModes::modes(double up_to) {
  if (sparse(up_to)) {
    if (!modes_ || modes_all_ || solved_up_to_ < up_to) {
      LowestModesOptions o;
      o.below_omega = up_to;
      LowestModesSummary s;
      const auto t0 = std::chrono::steady_clock::now();
      try {
        modes_ = lowest_modes(ops_.M, ops_.K, o, &s);
      } catch (const LowestModesFailure& e) {
        if (verbose_) io::progress("the starting model's modes: %s; solving densely\n", e.what());
        sparse_failed_ = true;
        return modes(up_to);
      }
      solved_up_to_ = up_to;
      modes_all_ = false;
      rigid_below_ = modes_->floor;
      if (verbose_)
        io::progress("the starting model's %d modes below %.4g Hz: sparse subspace iteration on %d degrees of freedom, %d "
                     "iterations, %.2g s\n",
                     s.wanted, up_to / (2.0 * M_PI), model_.ndof, s.iterations,
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    return *modes_;
  }
  if (!modes_all_) {
    if (verbose_ && model_.ndof >= kSparseModesFrom)
      io::progress("the starting model's modes: a dense eigen-solution of %d degrees of freedom, about %.2g s (O(n^3); fewer "
                   "elements are faster)\n",
                   model_.ndof, dense_eigen_seconds(model_.ndof, true));
    modes_ = natural_modes(ops_.M, ops_.K);
    modes_all_ = true;
  }
  return *modes_;
}

DataContent data_content(const StructuralModel& model, const Parameterization& params,
                         const std::vector<io::Signal>& signals, double t_end, double sample_interval,
                         bool from_data) {
  StartModes start(model, params);
  return data_content(start, signals, t_end, sample_interval, from_data);
}

DataContent data_content(StartModes& start, const std::vector<io::Signal>& signals, double t_end, double sample_interval,
                         bool from_data) {
  const StructuralModel& model = start.model();
  const Parameterization& params = start.params();
  const AssembledModel& ops = start.ops();
  DataContent d;
  d.nyquist = M_PI / sample_interval;
  // K and ω_K from the frequencies alone (modes below start.rigid_below() count as rigid).
  {
    const std::vector<double>& w = start.frequencies(d.nyquist);
    std::vector<double> below;
    for (double x : w)
      if (x > start.rigid_below() && x <= d.nyquist) below.push_back(x);
    d.modes_below_nyquist = static_cast<int>(below.size());
    if (below.empty()) return d;
    d.omega_first = below.front();
    d.mode = std::min(d.modes_below_nyquist, params.size() + 2);
    d.omega = below[static_cast<std::size_t>(d.mode - 1)];
  }
  // The visible content K_data (reported): from the mode shapes.
  const NaturalModes& m = start.modes(d.nyquist);
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
// modes 1 … count (all below up_to) at the starting parameters; 0 if none is damped.
double smallest_modal_damping(StartModes& start, int count, double up_to) {
  const NaturalModes& m = start.modes(up_to);
  const MatrixXd D(start.ops().D);
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
  StartModes start(model, params);
  return identifier_integration(sc, start, signals);
}

IdentifierStep identifier_integration(const io::Scenario& sc, StartModes& start, const std::vector<io::Signal>& signals) {
  if (sc.identification.time_step > 0) return {sc.identification.time_step, -1, sc.identification.time_step};
  // Resolve (ω h <= 0.3) modes 1 … K, K = min(P + 2, modes below Nyquist) (data_content): an
  // L-stable step damps what it does not resolve, keeping its quasi-static part.
  const DataContent content = data_content(start, signals, sc.simulation.duration, sc.simulation.sample_interval,
                                           sc.identification.step_rule == io::StepRule::Data);
  const double w = content.omega;
  double h = sc.simulation.sample_interval;
  if (w > 0) h = std::min(h, 0.3 / w);
  // A damping parameter is read from decay rates: the step's own damping in that band must be
  // small against the physical one, ζ_num(ω_K h) <= 1 % of the smallest modal damping ratio
  // there (docs/theory.md §5.2), or the fit absorbs the integrator's damping into the estimate.
  IdentifierStep out{h, -1, h};
  if (w > 0 && estimates_damping(start.model(), start.params())) {
    const double target = 0.01 * smallest_modal_damping(start, content.mode, content.nyquist);
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
std::unique_ptr<Problem> problem_skeleton(const io::Scenario& sc, bool verbose) {
  check_scenario(sc);
  auto p = std::make_unique<Problem>();
  p->build_progress = verbose;
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



// Synthetic data: the truth's structure (truth.overrides applied) on a finer mesh, with a step 4x
// finer than the identifier's. Returns the identifier's step.
IdentifierStep synthesize_data(Problem& p) {
  const auto& sc = p.scenario;
  const auto& id = sc.identification;
  const int data_elements = id.data_elements > 0 ? id.data_elements : 2 * id.elements;
  StartModes start(p.model(), *p.params, p.build_progress);
  const IdentifierStep is = identifier_integration(sc, start, p.signals);
  const double step = is.step;
  p.content = data_content(start, p.signals, sc.simulation.duration, sc.simulation.sample_interval, id.step_rule == io::StepRule::Data);
  check_identifier_step(sc, p.model(), *p.params, p.signals, p.content, step, true);
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
IdentifierStep measured_data_step(Problem& p) {
  const auto& sc = p.scenario;
  StartModes start(p.model(), *p.params, p.build_progress);
  const IdentifierStep is = identifier_integration(sc, start, p.signals);
  p.content = data_content(start, p.signals, sc.simulation.duration, sc.simulation.sample_interval,
                           sc.identification.step_rule == io::StepRule::Data);
  check_identifier_step(sc, p.model(), *p.params, p.signals, p.content, is.step, false);
  check_record_span(p, is.step);
  return is;
}

// identification.band (inverse/band_filter.h): the inputs' samples at the data's times and the
// data filtered alike; the stated noise levels become the filtered data's.
void apply_band(Problem& p) {
  const auto& band = p.scenario.identification.band;
  if (band.empty()) return;
  check_band(p);
  const auto& t = p.data.t;
  const double dt = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
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
  if (!p.measured() || !id.band.empty() || id.band_mode != io::IdentificationSpec::BandMode::Auto || id.model != io::Model::Linear) return;
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
  if (!p.measured() || t.size() < 4) return;
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
  check_record_levels(p, csv);
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
  p.objective_options.solver.integrator = id.integrator;
  if (id.initial_state == io::InitialState::Estimate) {  // esdirk, not Krylov (the door: check_scenario)
    // The flexible modes the step resolves (the data's content, docs/theory.md §5.2), or as stated.
    p.objective_options.initial_state_modes =
        id.initial_state_modes > 0 ? id.initial_state_modes
                                   : std::clamp(p.content.mode, 1, io::kMaxInitialStateModes);
  }
}


// The problem from measured data: the table's columns, the metadata beside it.
std::unique_ptr<Problem> from_table(std::unique_ptr<Problem> p, const io::DataTable& table, const std::string& source,
                                    const io::TruthMeta* meta, const std::string& meta_source) {
  p->origin = Problem::DataOrigin::Record;
  const std::map<std::string, double> meta_truth = read_record(*p, table, source, meta, meta_source);
  if (!meta_truth.empty()) {
    io::Scenario truth_sc = p->scenario;
    io::set_structure_parameters(truth_sc, meta_truth);
    set_true_values(*p, truth_sc);
  }
  const bool frequency = p->scenario.identification.domain == io::Domain::Frequency;
  finish_problem(*p, frequency ? IdentifierStep{} : measured_data_step(*p), &source);
  return p;
}

}  // namespace

std::unique_ptr<Problem> make_problem(const io::Scenario& sc, const io::DataTable& table, const std::string& source,
                                      const io::TruthMeta* meta, const std::string& meta_source, bool verbose) {
  return from_table(problem_skeleton(sc, verbose), table, source, meta, meta_source);
}

std::unique_ptr<Problem> make_problem(const io::Scenario& sc, const std::optional<std::string>& data_csv, bool verbose) {
  auto p = problem_skeleton(sc, verbose);
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
      p->origin = Problem::DataOrigin::FrfFile;
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
