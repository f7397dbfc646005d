#pragma once
// Scenario -> Simbody structure -> trajectory table + metadata (the truth.csv / truth.json of
// docs/theory.md §10, written through scoleid::io).
//
// The equations integrated are the structure's multibody equations of motion (beam_chain.h,
// scole_system.h) under the scenario's inputs, from rest in the undeformed configuration.
// Integration stops at every input breakpoint (io::Signal::breakpoints) and restarts there,
// so no step straddles a jump in f or f'. Samples are taken at k * dt, k = 0..floor(T/dt),
// dt = truth.output_interval or simulation.sample_interval, by the integrator's interpolant.
// With truth.anti_alias_hz the samples are taken 8 times denser (kAntiAliasOversample), every
// channel passes an 8-pole Butterworth low-pass at that corner (a DAQ's anti-alias filter), and
// every 8th sample is kept; the noise below is added after (ADC noise).
// Sensor errors (truth.overrides.sensors): bias + drift·t added to each noise-free read-out.
// Sensor noise: N(0, noise_std^2), one std::mt19937_64 seeded with simulation.seed, drawn
// column by column (sensors in scenario order, samples in time order) for sensors with
// noise_std > 0; inputs are never noisy.
//
// Plausibility guards (docs/truth-guards.md), checked at every sample: the identifier's model is
// linear, so a truth that leaves its range is refused rather than written. A proof mass further
// than scole.actuator_stroke from the centre of either slider, or (unless truth.large_motion) a
// rotation beyond kSmallRotationBound, ends the run with PlausibilityError.
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Simbody.h>

#include "scoleid/io/data_files.h"
#include "scoleid/io/run_directory.h"
#include "scoleid/io/scenario.h"
#include "scoleid/model/structure.h"

namespace scoleid::model {

// Integrators by name: gauss-legendre (gauss_legendre.h), trapezoidal (trapezoidal.h), Simbody's
// rk-merson, rk-feldberg, rk3, cpodes, cpodes-bdf2, verlet, semi-explicit-euler2, and "auto" =
// choose_integrator().
extern const char* const kDefaultIntegrator;
// "auto": the step of every method is bounded by the chain's fastest eigenvalue lambda_max of
// the linearisation about the initial state (linearisation.h). If it is well damped
// (-Re/|lambda| >= 0.5: Kelvin–Voigt damping makes the top chain modes overdamped, as in
// paper-beam-2), the stiffness is dissipative and BDF (cpodes) steps over it; otherwise the top
// modes ring (SCOLE's zeta, undamped beams), BDF orders > 2 go unstable on them, BDF2 damps the
// response, and an A-stable method whose amplification on an undamped mode has modulus one is
// needed. It must not project onto constraints, so a constrained chain (simple supports) takes the
// explicit kDefaultIntegrator (rk-merson) instead. Unconstrained: two-stage Gauss–Legendre
// (gauss_legendre.h) when the run starts at rest in the default configuration, as every truth run
// does, whatever its inputs (step, bang-bang and pulse loads included: their trajectories are
// closer to a tight RK-Merson reference than the trapezoidal rule's, in a third of the time,
// docs/theory.md §9.5); the trapezoidal rule (trapezoidal.h) for a chain started deformed or
// moving, whose top modes carry energy from the start: Gauss–Legendre's step follows the
// fundamental alone and leaves their nonlinear coupling unresolved (energy drift 1e-4 where the
// trapezoidal rule keeps 1e-6, conservation_test.cpp).
std::string choose_integrator(const SimTK::MultibodySystem& system, const SimTK::State& state);
std::vector<std::string> integrator_names();
std::unique_ptr<SimTK::Integrator> make_integrator(const std::string& name, const SimTK::System& system,
                                                   double accuracy);

// Builds the beam chain or the SCOLE system of the scenario with `segments` segments.
std::unique_ptr<Structure> build_structure(const io::Scenario& scenario, int segments);
// build_structure plus the scenario's inputs as a force element, topology realized: ready for
// getDefaultState() (rest, undeformed) and simulate(). InputError if an input cannot apply.
std::unique_ptr<Structure> prepare_structure(const io::Scenario& scenario, int segments);

struct SimulateOptions {
  std::string integrator = "auto";
  double accuracy = 1e-9;
  double final_time = 1.0;
  double sample_interval = 0.01;
  std::vector<double> breakpoints;   // times where the inputs jump
  bool progress = false;             // percent and real-time factor on stderr
  double wall_limit = 0.0;           // seconds; > 0: stop early (Termination::WallLimit)
  double max_step = 0.0;             // trapezoidal, gauss-legendre: step bound, 0 = from accuracy
  double reference_omega = 0.0;      // trapezoidal, gauss-legendre: omega of the step rule (the fundamental, or the fastest mode the inputs excite, weighed: docs/theory.md §9.5), 0 = from the initial state
  // The stage on_sample reads (Velocity when no sensor reads accelerations): gauss-legendre then
  // realizes its step ends no further. The other methods deliver Acceleration always.
  SimTK::Stage sample_stage = SimTK::Stage::Acceleration;
  bool IsValid(std::string* why) const;
};

struct SimulateSummary {
  enum class Termination { Completed, WallLimit };
  Termination termination = Termination::Completed;
  std::string message;
  std::string integrator;
  int samples = 0;
  int steps_taken = 0;
  int steps_attempted = 0;
  int realizations = 0;
  double max_step = 0.0;             // trapezoidal, gauss-legendre: the largest step taken
  double simulated_seconds = 0.0;
  double wall_seconds = 0.0;
  double real_time_factor() const { return wall_seconds > 0 ? simulated_seconds / wall_seconds : 0.0; }
  std::string BriefReport() const;
};

// Integrates `system` from `initial` (realized or not) and calls on_sample(state) at every
// sample time with the state realized to options.sample_stage at least. Throws std::runtime_error on failure.
// With a wall_limit it may stop early: then termination == WallLimit and simulated_seconds is
// the time reached.
SimulateSummary simulate(const SimTK::MultibodySystem& system, const SimTK::State& initial,
                         const SimulateOptions& options,
                         const std::function<void(const SimTK::State&)>& on_sample);

// The truth left the range of the identifier's linear model (docs/truth-guards.md): one line
// naming the scenario, the body or actuator, the quantity, the bound and the time. scole-truth
// maps it, like every run failure, to exit code 1; nothing is written.
class PlausibilityError : public std::runtime_error {
public:
  explicit PlausibilityError(const std::string& what) : std::runtime_error(what) {}
};

// The small-rotation bound (rad) on the shuttle's attitude (relative to the inertial frame), on
// every mast segment and the reflector relative to the shuttle, and on every beam segment and tip
// body relative to ground. At 0.1 rad sin θ = θ to 0.17 % and the second-order terms a linear
// model drops (1 − cos θ ≈ θ²/2 against θ) are 5 % of the first-order ones (docs/truth-guards.md).
inline constexpr double kSmallRotationBound = 0.1;

// With truth.anti_alias_hz: how many times denser than the output the truth samples before its
// anti-alias filter. The corner then lies below 1/16 of the dense rate, and what the filter does not
// stop folds from above 7/16 of it.
inline constexpr int kAntiAliasOversample = 8;

struct TruthOptions {
  int segments = 0;            // 0 = scenario truth.segments
  std::string integrator;      // "" = scenario truth.integrator
  double accuracy = 0.0;       // 0 = scenario truth.accuracy
  bool progress = false;
  bool visualize = false;      // show the run in simbody-visualizer (needs a display)
  bool IsValid(std::string* why) const;
};

struct TruthResult {
  io::DataTable table;
  io::TruthMeta meta;
  SimulateSummary summary;
};

// Simulates io::truth_scenario(scenario): the structure with truth.overrides applied; truth.json's
// true_parameters are the values it used. Throws io::InputError for a scenario the truth cannot
// represent, PlausibilityError when the motion leaves the identifier's linear range (a guard
// above), std::runtime_error when the integration fails.
TruthResult run_truth(const io::Scenario& scenario, const TruthOptions& options = {});
// truth.csv and truth.json into the run directory's staging area; the caller commits them as one
// unit (io/run_directory.h), so the two files always come from the same run.
void write_truth(const TruthResult& result, io::RunDirectory& dir);
inline std::vector<std::string> output_files() { return {"truth.csv", "truth.json"}; }

// The physical true parameters as truth.json reports them.
std::map<std::string, double> true_parameters(const io::Scenario& scenario);

}  // namespace scoleid::model
