// SCOLE built-in scenarios (docs/theory.md §3.6), slug-ft-s, nominal configuration (the `scole:` defaults).
// Excitation as in the paper (Fig. 6): a force and a moment at the antenna (reflector) end.
// Haversine pulses of about half the period of the mode they target: the first bending pair
// (about 0.3 Hz, roll and pitch) and the first torsion mode (about 0.5 Hz, the reflector's
// offset inertia on GJ). Sensors: roll and pitch displacement of the mast tip (shuttle y and x)
// and the tip torsion (the reflector's rotation about the mast axis z relative to the shuttle).
//
// paper-scole-2 estimates ζ as the paper's Case II does, but no excitation of this kind lets
// the identifier determine it. With c = 2ζ√(ρA·EI) a bending mode of wavenumber β has the
// damping ratio ζβ²: 3e-7 in the first bending pair, 1e-6…1e-5 up to 12 Hz, so doubling ζ moves
// these outputs by 4e-5 of the signal over 20 s — less than the identifier's own discretisation
// residual (6e-5), whose L-stable step alone damps the first pair by about half of ζβ² and the
// higher modes by more than ζβ². A short, sharp pulse reaches higher modes, where ζβ² is larger,
// but they must then be resolved in space and time: with such pulses, six more rotation sensors
// along the mast, 80 elements and a 5e-4 s step (40 000 steps, 25 s for the data alone) ζ moves
// the outputs by 5e-4…1.4e-3 of the signal against a residual of 3e-4…1.2e-3, and a model error of
// the residual's size could still shift ζ by 60–90 %. So the pulses stay those of the paper's
// Fig. 6, and the identifier reports ζ as not identifiable (identify/identifiability.h).
#include "scoleid/io/builtin.h"

namespace scoleid::io {

namespace {
// None of these scenarios drives the proof-mass actuators. Their free proof masses stay where they
// are while the structure's rigid motion carries the mast past them, so each scenario states a
// stroke beyond that drift (measured over its record) instead of the default travel of a driven
// actuator; the guard stays armed against a runaway (docs/truth-guards.md).
constexpr const char* kPassiveActuators = R"(# Passive proof masses: the roll the reflector pulses leave (0.016 rad at 20 s) carries the mast
# 1.3 ft past the outer one over the record; the stroke leaves about four times that.
scole: {actuator_stroke: 5}
)";
// Paper Case I: its sensors, and its parameters from its start (also driven by the slew).
constexpr const char* kCaseOneSensors = R"(sensors:
  - {name: roll_tip, at: mast, kind: displacement, location: 130, direction: y, unit: ft}
  - {name: pitch_tip, at: mast, kind: displacement, location: 130, direction: x, unit: ft}
  - {name: yaw_tip, at: reflector, kind: rotation, direction: z, unit: rad}
simulation: {duration: 20, sample_interval: 0.01, seed: 1}
)";
constexpr const char* kCaseOneIdentification = R"(identification:
  parameterization: paper
  estimate: [q1, q2]
  initial: {rho_A: 0.085, EI: 3.6e7}
  elements: 10
)";
constexpr const char* kExcitation = R"(inputs:
  - {name: F_x, at: reflector, kind: force, direction: x, unit: lb, signal: {type: haversine, amplitude: 10, t0: 0, width: 1.5}}
  - {name: F_y, at: reflector, kind: force, direction: y, unit: lb, signal: {type: haversine, amplitude: 10, t0: 0.5, width: 1.5}}
  - {name: M_z, at: reflector, kind: moment, direction: z, unit: lb ft, signal: {type: haversine, amplitude: 200, t0: 0, width: 1}}
)";
}  // namespace

std::vector<BuiltinScenario> scole_builtin_scenarios() {
  return {
      {"paper-scole-1",
       "Paper SCOLE Case I: q1 = EI/rho_A, q2 = 1/rho_A from force and moment pulses at the reflector",
       std::string(R"(name: paper-scole-1
description: "Paper SCOLE Case I: q1 = EI/rho_A, q2 = 1/rho_A; force and moment pulses at the reflector"
structure: scole
)") + kPassiveActuators + kExcitation + kCaseOneSensors + kCaseOneIdentification + R"(truth: {segments: 40}
)"},
      {"paper-scole-2",
       "Paper SCOLE Case II: EI, rho_A, rho_I_psi, zeta (physical) from force and moment pulses at the reflector",
       std::string(R"(name: paper-scole-2
description: "Paper SCOLE Case II: EI, rho_A, rho_I_psi, zeta; force and moment pulses at the reflector"
structure: scole
)") + kPassiveActuators + kExcitation + R"(sensors:
  - {name: roll_tip, at: mast, kind: displacement, location: 130, direction: y, unit: ft}
  - {name: pitch_tip, at: mast, kind: displacement, location: 130, direction: x, unit: ft}
  - {name: yaw_tip, at: reflector, kind: rotation, direction: z, unit: rad}
  - {name: roll_mid, at: mast, kind: displacement, location: 65, direction: y, unit: ft}
  - {name: pitch_mid, at: mast, kind: displacement, location: 65, direction: x, unit: ft}
  - {name: yaw_mid, at: mast, kind: rotation, location: 65, direction: z, unit: rad}
simulation: {duration: 20, sample_interval: 0.01, seed: 1}
identification:
  parameterization: physical
  estimate: [EI, rho_A, rho_I_psi, zeta]
  initial: {EI: 3.2e7, rho_A: 0.075, rho_I_psi: 1.1, zeta: 0.0025}
  # Torsion's linear elements: at 10 elements their discretisation moves rho_I_psi by 1.1e-4.
  elements: 20
truth: {segments: 40}
)"},
      {"scole-slew",
       "20 deg shuttle roll slew, bang-bang roll moment over 10 s, then 10 s of residual vibration",
       R"(name: scole-slew
description: "20 deg rest-to-rest shuttle roll slew (bang-bang moment), nonlinear rigid-flexible coupling"
structure: scole
# Rest-to-rest rigid slew: theta = A w^2 / (4 I_roll). With I_roll = 1.204413e6 slug ft^2 (the
# whole SCOLE about the roll axis through the system CM), A = 16817 lb ft and w = 10 s give 20 deg.
# Passive proof masses: the mast sweeps past them through the slew, up to 36 ft at the outer one
# over the record; the stroke leaves about three times that.
scole: {actuator_stroke: 100}
inputs:
  - {name: M_roll, at: shuttle, kind: moment, direction: x, unit: lb ft, signal: {type: bangbang, amplitude: 16817, t0: 0, width: 10}}
sensors:
  - {name: roll, at: shuttle, kind: rotation, direction: x, unit: rad}
  - {name: roll_tip, at: mast, kind: displacement, location: 130, direction: y, unit: ft}
  - {name: pitch_tip, at: mast, kind: displacement, location: 130, direction: x, unit: ft}
  - {name: yaw_tip, at: reflector, kind: rotation, direction: z, unit: rad}
  - {name: los_x, at: reflector, kind: line_of_sight, direction: x, unit: rad}
  - {name: acc_tip_y, at: mast, kind: acceleration, location: 130, direction: y, unit: ft/s^2}
simulation: {duration: 20, sample_interval: 0.01, seed: 1}
identification:
  parameterization: physical
  estimate: [EI, rho_A]
  initial: {EI: 3.6e7, rho_A: 0.085}
  elements: 10
# A large-motion study: the shuttle turns 0.35 rad, beyond the small-rotation bound.
truth: {segments: 40, large_motion: true}
)"},
      {"scole-slew-case1",
       "paper Case I (q1, q2 and its three sensors) on the 20 deg roll slew, with the nonlinear model",
       std::string(R"(name: scole-slew-case1
description: "Paper SCOLE Case I on the 20 deg roll slew of scole-slew: the identifier's nonlinear model"
structure: scole
scole: {actuator_stroke: 100}
# The commanded bang-bang moment is known: the model is driven by it, not by the data's sampled
# column (piecewise linear between samples, each switch would move by half a sample, 5 ms: +0.6 %
# on q1 and q2 from the ringing's phase; docs/theory.md §11.3).
inputs:
  - {name: M_roll, at: shuttle, kind: moment, direction: x, unit: lb ft, signal: {type: bangbang, amplitude: 16817, t0: 0, width: 10}, signal_from: scenario}
)") + kCaseOneSensors + kCaseOneIdentification + R"(  # Finite shuttle rotation, the mast deflecting in the shuttle's rotating frame (docs/theory.md §3.8).
  model: nonlinear
truth: {segments: 40, large_motion: true}
)"},
  };
}

}  // namespace scoleid::io
