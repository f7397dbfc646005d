#include "scoleid/model/truth_run.h"

#include <algorithm>
#include <complex>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <unistd.h>
#include <random>
#include <sstream>
#include <type_traits>
#include <stdexcept>

#include "scoleid/io/band_filter.h"
#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/scenario_fields.h"
#include "scoleid/io/structure_parameters.h"
#include "scoleid/model/beam_chain.h"
#include "scoleid/model/frame_system.h"
#include "scoleid/model/inputs.h"
#include "scoleid/model/linearisation.h"
#include "scoleid/model/scole_system.h"
#include "scoleid/model/sensors.h"
#include "scoleid/model/gauss_legendre.h"
#include "scoleid/model/trapezoidal.h"

namespace scoleid::model {

using namespace SimTK;

// For constrained chains (simple supports), where the trapezoidal rule does not apply: of
// Simbody's integrators the only one that meets the energy criterion (drift < 1e-6 over 50
// periods, at accuracy 1e-8) within budget (scole-truth-bench). The chain's top modes bound its
// step; BDF orders > 2 go unstable on those lightly damped modes and crawl, BDF2 is dissipative.
const char* const kDefaultIntegrator = "rk-merson";

std::vector<std::string> integrator_names() {
  return {"auto", "gauss-legendre", "trapezoidal", "rk-merson", "rk-feldberg", "rk3", "cpodes", "cpodes-bdf2", "verlet",
          "semi-explicit-euler2"};
}

namespace {
// A state at rest at the default configuration: u = 0 and q = the system's default q.
bool starts_at_rest(const MultibodySystem& system, const State& state) {
  const State& d = system.getDefaultState();
  if (state.getNQ() != d.getNQ() || state.getNU() != d.getNU()) return false;
  for (int i = 0; i < state.getNU(); ++i)
    if (state.getU()[i] != 0.0) return false;
  for (int i = 0; i < state.getNQ(); ++i)
    if (state.getQ()[i] != d.getQ()[i]) return false;
  return true;
}
}  // namespace

std::string choose_integrator(const MultibodySystem& system, const State& state) {
  if (state.getNU() == 0) return kDefaultIntegrator;
  State eq = state;
  eq.updU() = 0.0;
  Eigen::MatrixXd A = state_jacobian(system, eq);
  const Eigen::VectorXcd lambda =
      io::interruptible([A = std::move(A)]() -> Eigen::VectorXcd { return Eigen::EigenSolver<Eigen::MatrixXd>(A, false).eigenvalues(); });
  std::complex<double> top = 0.0;
  for (int i = 0; i < lambda.size(); ++i)
    if (std::abs(lambda[i]) > std::abs(top)) top = lambda[i];
  const double damping = std::abs(top) > 0 ? -top.real() / std::abs(top) : 0.0;
  if (damping >= 0.5) return "cpodes";
  if (system.getMatterSubsystem().getNumConstraints() > 0) return kDefaultIntegrator;
  return starts_at_rest(system, state) ? "gauss-legendre" : "trapezoidal";
}

std::unique_ptr<Integrator> make_integrator(const std::string& name, const System& system, double accuracy) {
  const std::string n = name == "auto" ? kDefaultIntegrator : name;
  std::unique_ptr<Integrator> integ;
  if (n == "rk-merson") integ = std::make_unique<RungeKuttaMersonIntegrator>(system);
  else if (n == "rk-feldberg") integ = std::make_unique<RungeKuttaFeldbergIntegrator>(system);
  else if (n == "rk3") integ = std::make_unique<RungeKutta3Integrator>(system);
  else if (n == "cpodes") integ = std::make_unique<CPodesIntegrator>(system, CPodes::BDF, CPodes::Newton);
  else if (n == "cpodes-bdf2") {
    // BDF of order <= 2 is A-stable: lightly damped stiff chain modes (eigenvalues near the
    // imaginary axis) cannot destabilise it, as they do BDF3-5, which then crawls.
    auto c = std::make_unique<CPodesIntegrator>(system, CPodes::BDF, CPodes::Newton);
    c->setOrderLimit(2);
    integ = std::move(c);
  }
  else if (n == "verlet") integ = std::make_unique<VerletIntegrator>(system);
  else if (n == "semi-explicit-euler2") integ = std::make_unique<SemiExplicitEuler2Integrator>(system);
  else throw std::invalid_argument("unknown integrator '" + name + "'");
  integ->setAccuracy(accuracy);
  integ->setConstraintTolerance(std::min(1e-3, accuracy));
  integ->setAllowInterpolation(true);
  integ->setProjectInterpolatedStates(true);
  // stepTo() is called sample by sample; no internal cap (CPodes would otherwise print an
  // "mxstep" complaint every 500 steps).
  integ->setInternalStepLimit(100000000);
  return integ;
}

std::unique_ptr<Structure> build_structure(const io::Scenario& sc, int segments) {
  // The registry: scenario.structure -> its Simbody system (each factory in its kind's file).
  using Factory = std::unique_ptr<Structure> (*)(const io::Scenario&, int);
  static const std::map<io::Structure, Factory> registry = {
      {io::Structure::Beam, &make_beam_chain}, {io::Structure::Scole, &make_scole_system}, {io::Structure::Frame, &make_frame_system}};
  const auto it = registry.find(sc.structure);
  if (it == registry.end())
    io::fail_field(sc.source, "structure", "has no Simbody truth", "'" + std::string(io::to_string(sc.structure)) + "'");
  return it->second(sc, segments);
}

std::unique_ptr<Structure> prepare_structure(const io::Scenario& sc, int segments) {
  auto structure = build_structure(sc, segments);
  const auto inputs = resolve_inputs(sc, *structure);
  Force::Custom(structure->forces(), new InputForces(structure->matter(), structure->reference_body(), inputs));
  structure->system().realizeTopology();
  return structure;
}

bool SimulateOptions::IsValid(std::string* why) const {
  auto bad = [why](const std::string& m) { if (why) *why = m; return false; };
  if (!(accuracy > 0 && accuracy < 1)) return bad("accuracy must be in (0, 1)");
  if (!(final_time > 0)) return bad("final_time must be > 0");
  if (!(sample_interval > 0 && sample_interval <= final_time)) return bad("sample_interval must be in (0, final_time]");
  if (!(wall_limit >= 0)) return bad("wall_limit must be >= 0");
  if (!(max_step >= 0)) return bad("max_step must be >= 0");
  if (!(reference_omega >= 0)) return bad("reference_omega must be >= 0");
  const auto names = integrator_names();
  if (std::find(names.begin(), names.end(), integrator) == names.end())
    return bad("unknown integrator '" + integrator + "'");
  return true;
}

std::string SimulateSummary::BriefReport() const {
  std::ostringstream os;
  os << (termination == Termination::Completed ? "completed" : "stopped at the wall-time limit") << ": " << simulated_seconds
     << " s simulated in " << wall_seconds << " s wall (real-time factor " << real_time_factor() << "), "
     << integrator << ", " << steps_taken << " steps (" << steps_attempted << " attempted), "
     << realizations << " realizations, " << samples << " samples";
  if (!message.empty()) os << "; " << message;
  return os.str();
}

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The sample loop shared by every integrator: samples at t_start + k dt, k = 0..floor(T/dt); input
// breakpoints in between. advance(t_sample, t_breakpoint) moves the integrator forward, at most to
// the nearer of the two (t_breakpoint = Infinity when none is left) and restarting it at a
// breakpoint it reaches; time() is the integrator's time; current() its state realized to
// Acceleration. Fills samples and termination of `sum`.
void sample_loop(const SimulateOptions& opt, double t_start, Clock::time_point wall0,
                 const std::function<void(double, double)>& advance, const std::function<double()>& time,
                 const std::function<const State&()>& current, const std::function<void(const State&)>& on_sample,
                 SimulateSummary& sum) {
  std::vector<double> bps;
  for (double b : opt.breakpoints)
    if (b > t_start && b < opt.final_time) bps.push_back(b);
  std::sort(bps.begin(), bps.end());
  const int K = static_cast<int>(std::floor(opt.final_time / opt.sample_interval + 1e-9));
  double next_progress = 2.0;
  std::size_t ib = 0;
  // A failure mid-run (a guard, the integrator) ends the progress line first, so that its
  // message is a line of its own (an interrupt's message starts its own line: model/main.cpp).
  struct EndProgressLine {
    const SimulateOptions& opt;
    const double& next_progress;
    ~EndProgressLine() {
      if (std::uncaught_exceptions() > 0 && io::interrupt_signal() == 0 && opt.progress && next_progress > 2.0)
        std::fprintf(stderr, "\n");
    }
  } end_progress_line{opt, next_progress};
  for (int k = 0; k <= K; ++k) {
    const double tk = std::min(t_start + k * opt.sample_interval, opt.final_time);
    const double eps = 1e-12 * std::max(1.0, std::abs(tk));
    io::check_interrupt();  // SIGINT/SIGTERM: end between samples, nothing written (io/interrupt.h)
    while (time() < tk - eps) {
      while (ib < bps.size() && bps[ib] <= time() + eps) ++ib;
      advance(tk, ib < bps.size() ? bps[ib] : Infinity);
      if (opt.progress && seconds_since(wall0) > next_progress) {
        std::fprintf(stderr, "\r%5.1f%% of %g s simulated, real-time factor %.2f   ", 100.0 * time() / opt.final_time,
                     opt.final_time, time() / seconds_since(wall0));
        next_progress = seconds_since(wall0) + 2.0;
      }
    }
    on_sample(current());
    ++sum.samples;
    if (opt.wall_limit > 0 && seconds_since(wall0) > opt.wall_limit) {
      sum.termination = SimulateSummary::Termination::WallLimit;
      break;
    }
  }
  if (opt.progress && next_progress > 2.0) std::fprintf(stderr, "\n");
}

// simulate() on one of the implicit fixed-step methods (trapezoidal.h, gauss_legendre.h): steps
// end on every sample time and every input breakpoint.
template <class Integrator, class Options>
void simulate_fixed_step(const MultibodySystem& system, const State& initial, const SimulateOptions& opt,
                         const std::function<void(const State&)>& on_sample, Clock::time_point wall0,
                         SimulateSummary& sum, const char* error_formula) {
  Options to;
  to.accuracy = opt.accuracy;
  to.max_step = opt.max_step;
  to.reference_omega = opt.reference_omega;
  if constexpr (std::is_same_v<Options, GaussLegendreOptions>) to.output_stage = opt.sample_stage;
  Integrator integ(system, initial, to);
  const double eps = 1e-12 * std::max(1.0, opt.final_time);
  sample_loop(
      opt, initial.getTime(), wall0,
      [&](double tk, double tb) {
        if (tb < tk + eps) integ.advance_to(tb, true);
        else integ.advance_to(tk);
      },
      [&] { return integ.time(); }, [&]() -> const State& { return integ.state(); }, on_sample, sum);
  const auto& ts = integ.summary();
  sum.steps_taken = sum.steps_attempted = ts.steps;
  sum.realizations = ts.realizations;
  sum.simulated_seconds = integ.time() - initial.getTime();
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "step %.4g s, %d Newton corrections, %d Jacobians, %d factorizations; frequency error "
                "%s = %.2g at %.4g Hz (the fastest mode the inputs excite, weighed by its share of the record, or the fastest input sine)",
                ts.largest_step, ts.newton_iterations, ts.jacobians, ts.factorizations, error_formula,
                ts.lowest_mode_frequency_error(), ts.lowest_omega / (2 * Pi));
  sum.message = buf;
  if constexpr (std::is_same_v<Options, GaussLegendreOptions>) {
    if (ts.split_steps > 0) sum.message += "; " + std::to_string(ts.split_steps) + " steps split in two (Newton failed)";
    if (ts.roundoff_limited_steps > 0) {
      std::snprintf(buf, sizeof buf, "; %d steps ended at the residual's round-off (largest correction %.2g of the state scale)",
                    ts.roundoff_limited_steps, ts.largest_roundoff_correction);
      sum.message += buf;
    }
  }
  sum.max_step = ts.largest_step;
}

// simulate() on one of Simbody's integrators, stopped at every breakpoint and restarted there.
void simulate_simbody(const MultibodySystem& system, const State& initial, const SimulateOptions& opt,
                      const std::function<void(const State&)>& on_sample, Clock::time_point wall0,
                      SimulateSummary& sum) {
  auto integ = make_integrator(sum.integrator, system, opt.accuracy);
  integ->setFinalTime(opt.final_time);
  integ->initialize(initial);
  sample_loop(
      opt, initial.getTime(), wall0,
      [&](double tk, double tb) {
        const Integrator::SuccessfulStepStatus st = integ->stepTo(tk, tb);
        if (integ->isSimulationOver() && integ->getTerminationReason() != Integrator::ReachedFinalTime)
          throw std::runtime_error("integration failed at t = " + io::format_value(integ->getTime()) + ": " +
                                   Integrator::getTerminationReasonString(integ->getTerminationReason()));
        // Restart the method at the input discontinuity (no history carried across it), also where
        // the breakpoint is a sample time too (reported as the report time reached): a method that
        // kept the long steps of a structure at rest would step over the load.
        const bool at_breakpoint = std::isfinite(tb) && integ->getTime() >= tb - 1e-12 * std::max(1.0, std::abs(tb));
        if (st == Integrator::ReachedScheduledEvent || at_breakpoint) integ->reinitialize(Stage::Time, false);
      },
      [&] { return integ->getTime(); },
      [&]() -> const State& {
        system.realize(integ->getState(), Stage::Acceleration);
        return integ->getState();
      },
      on_sample, sum);
  sum.steps_taken = integ->getNumStepsTaken();
  sum.steps_attempted = integ->getNumStepsAttempted();
  sum.realizations = integ->getNumRealizations();
  sum.simulated_seconds = integ->getTime() - initial.getTime();
}
}  // namespace

SimulateSummary simulate(const MultibodySystem& system, const State& initial, const SimulateOptions& opt,
                         const std::function<void(const State&)>& on_sample) {
  std::string why;
  if (!opt.IsValid(&why)) throw std::invalid_argument("simulate: " + why);
  SimulateSummary sum;
  const auto wall0 = Clock::now();
  sum.integrator = opt.integrator == "auto" ? choose_integrator(system, initial) : opt.integrator;
  if (sum.integrator == "trapezoidal")
    simulate_fixed_step<TrapezoidalIntegrator, TrapezoidalOptions>(system, initial, opt, on_sample, wall0, sum,
                                                                   "(omega h)^2/12");
  else if (sum.integrator == "gauss-legendre")
    simulate_fixed_step<GaussLegendreIntegrator, GaussLegendreOptions>(system, initial, opt, on_sample, wall0, sum,
                                                                       "(omega h)^4/720");
  else simulate_simbody(system, initial, opt, on_sample, wall0, sum);
  sum.wall_seconds = seconds_since(wall0);
  return sum;
}

namespace {
// The Debian Simbody libraries are built without NDEBUG and so spawn "simbody-visualizer_d",
// while the package ships "simbody-visualizer". Offer the latter under the expected name through
// a private directory (a symlink), searched before Simbody's own list.
Array_<String> visualizer_search_path() {
  namespace fs = std::filesystem;
  Array_<String> path;
  for (const char* dir : {"/usr/lib/x86_64-linux-gnu/simbody/libexec", "/usr/lib/simbody/libexec",
                          "/usr/libexec/simbody", "/usr/local/libexec/simbody"}) {
    const fs::path exe = fs::path(dir) / "simbody-visualizer";
    std::error_code ec;
    if (!fs::exists(exe, ec) || fs::exists(fs::path(dir) / "simbody-visualizer_d", ec)) continue;
    const fs::path link_dir = fs::temp_directory_path() / ("scoleid-visualizer-" + std::to_string(::getpid()));
    fs::create_directories(link_dir, ec);
    fs::create_symlink(exe, link_dir / "simbody-visualizer_d", ec);
    path.push_back(String(link_dir.string() + "/"));
    break;
  }
  return path;
}
}  // namespace

namespace {
// A measured value or a sample time in a message: six significant digits (a sample time k dt
// carries rounding noise in its last bits).
std::string g6(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// The plausibility guards of run_truth (truth_run.h, docs/truth-guards.md), read off each sample.
class PlausibilityGuard {
public:
  PlausibilityGuard(const io::Scenario& scenario, const io::Scenario& truth, const Structure& st)
      : matter_(st.matter()), source_(truth.source) {
    if (st.actuator_count() > 0) {
      stroke_ = st.actuator_stroke();
      stroke_field_ = io::truth_field(scenario, truth, std::string(io::to_string(st.kind())) + ".actuator_stroke");
      for (int k = 1; k <= st.actuator_count(); ++k)
        for (int axis = 0; axis < 2; ++axis) {
          const MobilizedBodyIndex b = st.actuator_slider(k, axis);
          if (b.isValid()) sliders_.push_back({b, "actuator" + std::to_string(k), axis == 0 ? "x" : "y"});
        }
    }
    if (truth.truth.large_motion) return;
    const MobilizedBodyIndex ref = st.reference_body();
    const std::string rel = ref == GroundIndex ? "relative to ground" : "relative to the " + st.reference_name();
    if (ref != GroundIndex) rotations_.push_back({ref, GroundIndex, st.reference_name() + " attitude (relative to the inertial frame)"});
    const int n = st.segments();
    for (int i = 0; i < n; ++i)
      rotations_.push_back({st.segment_bodies()[static_cast<std::size_t>(i)], ref, st.segment_name(i) + " " + rel});
    if (st.tip_body().isValid())
      rotations_.push_back({st.tip_body(), ref, st.tip_name() + " " + rel});
  }

  // Throws PlausibilityError at the first slider beyond the stroke or rotation beyond the bound.
  void check(const State& s) const {
    for (const auto& sl : sliders_) {
      const double q = matter_.getMobilizedBody(sl.body).getOneQ(s, 0);
      if (std::abs(q) > stroke_)
        throw PlausibilityError(source_ + ": " + sl.actuator + " proof mass displaced " + g6(q) +
                                " along " + sl.axis + " relative to the mast at t = " + g6(s.getTime()) +
                                " s, beyond its stroke " + stroke_field_ + " = " + io::format_value(stroke_) +
                                " (docs/truth-guards.md)");
    }
    for (const auto& r : rotations_) {
      const Rotation R = matter_.getMobilizedBody(r.body).findBodyRotationInAnotherBody(
          s, matter_.getMobilizedBody(r.relative_to));
      const double angle = R.convertRotationToAngleAxis()[0];  // in [0, pi]
      if (angle > kSmallRotationBound)
        throw PlausibilityError(source_ + ": " + r.what + " rotated " + g6(angle) + " rad at t = " +
                                g6(s.getTime()) + " s, beyond the small-rotation bound " +
                                io::format_value(kSmallRotationBound) +
                                " rad of the identifier's linear model; a large-motion study sets "
                                "truth.large_motion: true (docs/truth-guards.md)");
    }
  }

private:
  struct Slider { MobilizedBodyIndex body; std::string actuator, axis; };
  struct Rotating { MobilizedBodyIndex body, relative_to; std::string what; };
  const SimbodyMatterSubsystem& matter_;
  std::string source_;
  double stroke_ = 0.0;
  std::string stroke_field_;
  std::vector<Slider> sliders_;
  std::vector<Rotating> rotations_;
};
}  // namespace

bool TruthOptions::IsValid(std::string* why) const {
  auto bad = [why](const std::string& m) { if (why) *why = m; return false; };
  if (segments < 0 || segments > io::limits::kMaxSegments)
    return bad("segments must be 0 (the scenario's) or in [2, " + std::to_string(io::limits::kMaxSegments) + "]");
  if (!(accuracy >= 0 && accuracy < 1)) return bad("accuracy must be 0 (the scenario's) or in (0, 1)");
  if (!integrator.empty()) {
    const auto names = integrator_names();
    if (std::find(names.begin(), names.end(), integrator) == names.end())
      return bad("unknown integrator '" + integrator + "'");
  }
  return true;
}

std::map<std::string, double> true_parameters(const io::Scenario& sc) { return io::structure_parameters(sc); }

namespace {
// The acquisition's anti-alias filter (truth.anti_alias_hz): the record, sampled every dt, passes
// an 8-pole Butterworth low-pass at f_c (io/band_filter.h) channel by channel, inputs and sensors
// alike, and every m-th sample is kept (k = 0, m, 2m, …: the output's own grid).
// simulation.record_start: the record keeps the samples at t >= t_rec (the run starts from rest at 0).
void drop_before(io::DataTable& tab, double t_rec, double dt) {
  if (!(t_rec > 0)) return;
  std::size_t k = 0;
  while (k < tab.t.size() && tab.t[k] < t_rec - 1e-9 * dt) ++k;
  tab.t.erase(tab.t.begin(), tab.t.begin() + static_cast<std::ptrdiff_t>(k));
  for (auto& c : tab.columns) c.erase(c.begin(), c.begin() + static_cast<std::ptrdiff_t>(k));
}

void anti_alias(io::DataTable& tab, double f_c, double dt, int m) {
  const io::BandFilter lowpass(0.0, f_c, dt);
  auto keep = [m](const std::vector<double>& x) {
    std::vector<double> y;
    y.reserve(x.size() / m + 1);
    for (std::size_t k = 0; k < x.size(); k += m) y.push_back(x[k]);
    return y;
  };
  tab.t = keep(tab.t);
  for (auto& c : tab.columns) {
    // The filter's tail after a channel falls idle decays without end (1e-64 of it seconds later);
    // below 1e-15 of the channel's largest value it is rounding, and an idle channel reads zero.
    double peak = 0.0;
    for (double v : c) peak = std::max(peak, std::abs(v));
    c = keep(lowpass.apply(c));
    for (double& v : c)
      if (std::abs(v) < 1e-15 * peak) v = 0.0;
  }
}
}  // namespace

namespace {
// Refusals before any work: an unknown integrator, an accuracy of 1 or more, a record of
// nothing (no sensor reads anything; from rest with no load nothing moves).
void check_truth_request(const io::Scenario& sc, const std::string& integrator, double accuracy) {
  const auto names = integrator_names();
  if (std::find(names.begin(), names.end(), integrator) == names.end()) {
    std::string list;
    for (const auto& x : names) list += (list.empty() ? "" : "|") + x;
    io::fail_field(sc.source, "truth.integrator", "must be one of " + list, "'" + integrator + "'");
  }
  if (!(accuracy < 1)) io::fail_field(sc.source, "truth.accuracy", "must be < 1", io::format_value(accuracy));
  if (sc.sensors.empty())
    io::fail_field(sc.source, "sensors", "must list at least one sensor: a truth records what its sensors read", "[]");
  if (std::all_of(sc.inputs.begin(), sc.inputs.end(), [](const io::InputSpec& in) { return in.signal.is_zero(); }))
    io::fail_field(sc.source, "inputs",
                   "must give at least one input a signal: the structure starts at rest, and without a load nothing moves",
                   sc.inputs.empty() ? "[]" : std::to_string(sc.inputs.size()) + " inputs without a signal");
}

// The frequency the implicit fixed-step methods' step must follow for the modes the inputs excite
// (docs/theory.md §9.5). Their phase error per step on a mode ω is (ωh)^p / c (p = 5 Gauss–Legendre,
// 3 trapezoidal); held to `accuracy` on the fundamental, it is weighed on mode k by the mode's share
// of the record, r_k = a_k / max_j a_j, with a_k = |F(f_k)| ω_k^(o−2): the inputs' spectrum there
// (the largest over the inputs, the largest within ±5 % of f_k: a mode's own bandwidth straddles a
// pulse's spectral zero) times the mode's response per unit force read by the fastest sensor kind
// (o = 2 accelerometers, 1 velocity and strain, 0 the others: a mode's displacement per unit force
// falls as 1/ω_k²). Mode k then needs ω_k r_k^(1/p) in place of ω_1. Only modes below `f_follow`
// are followed: the sample rate (the first band that folds into the record), or twice an
// anti-alias filter's corner (the fixed-step methods keep the others unamplified). Returns 0
// without a mode or an input.
double excited_mode_omega(const io::Scenario& sc, const std::vector<Mode>& modes, double final_time, double sample_interval,
                          double f_follow, double p) {
  int order = 0;
  for (const auto& se : sc.sensors) {
    if (se.kind == io::SensorKind::Acceleration) order = std::max(order, 2);
    if (se.kind == io::SensorKind::Velocity || se.kind == io::SensorKind::Strain) order = std::max(order, 1);
  }
  // Each input sampled eight times denser than the record (its spectrum below the record's sample
  // rate then holds little of what lies above four times it).
  const double dt = sample_interval / 8.0;
  const auto N = static_cast<std::size_t>(std::floor(final_time / dt)) + 1;
  std::vector<std::vector<double>> x;
  for (const auto& in : sc.inputs) {
    if (in.signal.is_zero()) continue;
    std::vector<double> v(N);
    for (std::size_t i = 0; i < N; ++i) v[i] = in.signal(static_cast<double>(i) * dt);
    x.push_back(std::move(v));
  }
  if (x.empty()) return 0.0;
  auto spectrum = [&](double f) {
    double best = 0.0;
    for (double scale : {0.95, 0.975, 1.0, 1.025, 1.05}) {
      const double w = 2 * Pi * f * scale * dt;
      for (const auto& v : x) {
        // Goertzel: |Σ v_i e^{−iwi}| in one pass.
        double s1 = 0.0, s2 = 0.0;
        const double c = 2.0 * std::cos(w);
        for (double vi : v) {
          const double s0 = vi + c * s1 - s2;
          s2 = s1;
          s1 = s0;
        }
        const double re = s1 - s2 * std::cos(w), im = s2 * std::sin(w);
        best = std::max(best, std::hypot(re, im));
      }
    }
    return best;
  };
  std::vector<std::pair<double, double>> share;  // (ω_k, a_k)
  double a_max = 0.0;
  for (const auto& m : modes) {
    if (!(m.omega > 0.0) || !(m.frequency_hz < f_follow)) continue;
    const double a = spectrum(m.frequency_hz) * std::pow(m.omega, order - 2);
    share.emplace_back(m.omega, a);
    a_max = std::max(a_max, a);
  }
  double omega = 0.0;
  if (!(a_max > 0.0)) return 0.0;
  for (const auto& [w, a] : share) omega = std::max(omega, w * std::pow(a / a_max, 1.0 / p));
  return omega;
}

// The integration plan: integrator, accuracy, horizon, sample interval (denser behind an
// anti-alias filter), breakpoints and, for the implicit fixed-step methods, the frequency their step follows.
// Inputs the samples cannot resolve and runs over the step limit are refused here.
SimulateOptions simulation_plan(const io::Scenario& sc, Structure& structure, State& state,
                                const std::string& integrator, double accuracy, int n) {
  SimulateOptions so;
  so.integrator = integrator;
  so.accuracy = accuracy;
  so.final_time = sc.simulation.duration;
  so.sample_interval = sc.truth.output_interval > 0 ? sc.truth.output_interval : sc.simulation.sample_interval;
  // An acquisition anti-alias filter (truth.anti_alias_hz) runs on samples kOversample times denser.
  const int oversample = sc.truth.anti_alias_hz > 0 ? kAntiAliasOversample : 1;
  so.sample_interval /= oversample;
  // A sine or chirp at or above the samples' Nyquist frequency would alias into the record (and a
  // step rule tied to the samples cannot follow it); refused, naming it.
  double f_input = 0.0;
  for (std::size_t i = 0; i < sc.inputs.size(); ++i) {
    const double f = sc.inputs[i].signal.highest_frequency();
    f_input = std::max(f_input, f);
    if (f >= 0.5 / so.sample_interval)
      io::fail_field(sc.source, "inputs[" + std::to_string(i) + "].signal.frequency",
                     "is at or above " + io::format_value(0.5 / so.sample_interval) +
                         " Hz, the Nyquist frequency of the truth's samples (every " + io::format_value(so.sample_interval) +
                         " s): the record would alias it (sample faster, or filter like a DAQ with truth.anti_alias_hz)",
                     io::format_value(f));
  }
  if (so.integrator == "auto") so.integrator = choose_integrator(structure.system(), state);
  if (so.integrator == "trapezoidal" || so.integrator == "gauss-legendre") {
    // The implicit fixed-step methods' step follows the structure's fundamental mode, free of the
    // inputs (a load acting at t = 0 adds slow modes of the accelerated system, e.g. of the proof masses).
    const auto bare = build_structure(sc, n);
    bare->system().realizeTopology();
    const auto modes = natural_modes(bare->system(), bare->system().getDefaultState());
    if (!modes.empty()) so.reference_omega = modes.front().omega;
    // ... and the fastest sine the inputs drive it with, whose forced response it must follow alike.
    so.reference_omega = std::max(so.reference_omega, 2 * Pi * f_input);
    // ... and every higher mode that reaches the record, as far as the inputs excite it (a hammer's
    // pulse rings the modes up to about 2 / its width).
    const double p_exp = so.integrator == "trapezoidal" ? 3.0 : 5.0;
    // Without an anti-alias filter the modes up to the sample rate fold into the record; behind one
    // those above twice its corner reach it 48 dB down or more (8 poles), and are not followed.
    const double f_follow = sc.truth.anti_alias_hz > 0 ? std::min(2.0 * sc.truth.anti_alias_hz, 0.5 / so.sample_interval)
                                                       : 1.0 / so.sample_interval;
    so.reference_omega = std::max(so.reference_omega, excited_mode_omega(sc, modes, so.final_time, so.sample_interval, f_follow, p_exp));
    // Its step is (12 accuracy)^(1/3) / omega_1 (trapezoidal.h) or (720 accuracy)^(1/5) / omega_1
    // (gauss_legendre.h) at most: refuse a run that would take more steps than io::limits allows
    // before starting it.
    const double phase = so.integrator == "trapezoidal" ? std::cbrt(12.0 * accuracy) : std::pow(720.0 * accuracy, 0.2);
    const double steps = so.final_time * so.reference_omega / phase;
    if (!(steps <= io::limits::kMaxSteps))
      io::fail_field(sc.source, "truth.accuracy",
                     "gives about " + io::format_value(std::ceil(steps)) + " " + so.integrator + " steps over " +
                         io::format_value(so.final_time) + " s (its step follows " +
                         io::format_value(so.reference_omega / (2 * Pi)) + " Hz, the fastest mode the inputs excite), more than the limit of " +
                         io::format_value(io::limits::kMaxSteps),
                     io::format_value(accuracy));
  }
  for (const auto& in : sc.inputs)
    for (double b : in.signal.breakpoints()) so.breakpoints.push_back(b);
  return so;
}

// Each sensor's noise (normal, its noise_std, from the scenario's seed), added after the
// acquisition filter; noise over 1000 times a sensor's RMS signal is refused.
void add_sensor_noise(const io::Scenario& sc, io::DataTable& tab) {
  std::mt19937_64 rng(sc.simulation.seed);
  for (std::size_t i = 0; i < sc.sensors.size(); ++i) {
    const double sd = sc.sensors[i].noise_std;
    if (!(sd > 0)) continue;
    // Noise a thousand times the sensor's own RMS signal leaves a record of noise: over the
    // 5e6 samples a record may hold, the signal's share of it would still be below the noise of
    // its own estimate. Refused (a wrong unit, or noise_std: 1e20) rather than written.
    const auto& col = tab.columns[sc.inputs.size() + i];
    double ms = 0.0;
    for (double v : col) ms += v * v;
    const double rms = col.empty() ? 0.0 : std::sqrt(ms / static_cast<double>(col.size()));
    if (rms > 0 && sd > 1e3 * rms)
      io::fail_field(sc.source, "sensors[" + std::to_string(i) + "].noise_std",
                     "is " + io::format_value(sd / rms) + " times the RMS signal " + io::format_value(rms) + " of sensor '" +
                         sc.sensors[i].name + "': the record would hold nothing but noise (at most 1000 times)",
                     io::format_value(sd));
    std::normal_distribution<double> noise(0.0, sd);
    for (double& v : tab.columns[sc.inputs.size() + i]) v += noise(rng);
  }

}

io::TruthMeta truth_meta(const io::Scenario& scenario, const io::Scenario& sc, const TruthResult& res, int n,
                         double accuracy) {
  io::TruthMeta m;
  m.scenario = sc.name;
  m.structure = io::to_string(sc.structure);
  for (const auto& in : sc.inputs)
    m.columns.push_back({in.name, in.unit, "input", io::to_string(in.kind), io::to_string(in.at), in.location, in.direction, 0.0});
  for (const auto& se : sc.sensors)
    m.columns.push_back({se.name, se.unit, "output", io::to_string(se.kind), io::to_string(se.at), se.location, se.direction, se.noise_std});
  m.true_parameters = true_parameters(sc);
  m.generator = {{"program", "scole-truth"},
                 {"segments", n},
                 {"integrator", res.summary.integrator},
                 {"accuracy", accuracy},
                 {"seed", sc.simulation.seed},
                 {"anti_alias_hz", sc.truth.anti_alias_hz},
                 {"lumping", "Hencky bar chain (joint springs from dual-cell compliance)"},
                 {"simbody_version", SCOLEID_SIMBODY_VERSION},
                 {"steps", res.summary.steps_taken},
                 {"wall_seconds", res.summary.wall_seconds},
                 {"real_time_factor", res.summary.real_time_factor()}};
  m.settings = io::to_json(scenario);
  return m;
}
}  // namespace

TruthResult run_truth(const io::Scenario& scenario, const TruthOptions& opt) {
  // The truth simulates the scenario's structure with truth.overrides applied; truth.json
  // reports the values it used and echoes the scenario with its overrides.
  const io::Scenario sc = io::truth_scenario(scenario);
  std::string why;
  if (!opt.IsValid(&why)) throw std::invalid_argument("run_truth: " + why);
  const int n = opt.segments > 0 ? opt.segments : sc.truth.segments;
  const std::string integrator = opt.integrator.empty() ? sc.truth.integrator : opt.integrator;
  const double accuracy = opt.accuracy > 0 ? opt.accuracy : sc.truth.accuracy;
  check_truth_request(sc, integrator, accuracy);

  auto structure = prepare_structure(sc, n);
  const auto sensors = resolve_sensors(sc, *structure);
  std::unique_ptr<Visualizer> viz;
  if (opt.visualize) {
    structure->system().setUseUniformBackground(true);
    viz = std::make_unique<Visualizer>(structure->system(), visualizer_search_path());
    viz->setMode(Visualizer::RealTime);
    structure->system().realizeTopology();
  }
  const double frame = 1.0 / 30.0;
  double next_frame = 0.0;
  State state = structure->system().getDefaultState();

  SimulateOptions so = simulation_plan(sc, *structure, state, integrator, accuracy, n);
  so.progress = opt.progress;
  // Only accelerometers read the Acceleration stage (sensors.h); the guards read positions.
  so.sample_stage = std::any_of(sensors.begin(), sensors.end(),
                                [](const ResolvedSensor& r) { return r.kind == io::SensorKind::Acceleration; })
                        ? Stage::Acceleration
                        : Stage::Velocity;
  const int oversample = sc.truth.anti_alias_hz > 0 ? kAntiAliasOversample : 1;

  TruthResult res;
  io::DataTable& tab = res.table;
  for (const auto& in : sc.inputs) tab.names.push_back(in.name);
  for (const auto& se : sc.sensors) tab.names.push_back(se.name);
  tab.columns.assign(tab.names.size(), {});
  const auto& matter = structure->matter();
  const PlausibilityGuard guard(scenario, sc, *structure);
  res.summary = simulate(structure->system(), state, so, [&](const State& s) {
    guard.check(s);
    tab.t.push_back(s.getTime());
    std::size_t j = 0;
    for (const auto& in : sc.inputs) tab.columns[j++].push_back(in.signal(s.getTime()));
    // The ideal read-out plus the sensor's own error (truth.overrides.sensors); noise below.
    for (std::size_t i = 0; i < sensors.size(); ++i)
      tab.columns[j++].push_back(read_sensor(matter, s, sensors[i]) + sensor_error(sc.sensors[i], s.getTime()));
    if (viz && s.getTime() >= next_frame) {
      viz->report(s);
      next_frame = s.getTime() + frame;
    }
  });

  if (oversample > 1) anti_alias(tab, sc.truth.anti_alias_hz, so.sample_interval, oversample);
  add_sensor_noise(sc, tab);
  drop_before(tab, sc.simulation.record_start, so.sample_interval * oversample);
  res.meta = truth_meta(scenario, sc, res, n, accuracy);
  return res;
}

void write_truth(const TruthResult& r, io::RunDirectory& dir) {
  io::write_csv(dir.path("truth.csv"), r.table);
  io::write_json_atomic(dir.path("truth.json"), io::to_json(r.meta));
}

}  // namespace scoleid::model
