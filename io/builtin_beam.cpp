// The paper's beam cases (docs/theory.md §2.4): L = 10 m, step load P = 10 N at t = 0+, zero initial
// state, horizon T = 10 s, SI units. The true values live in `beam:`, the paper's starting
// values in `identification.initial`. Case II's damping is the paper's Kelvin–Voigt term: its
// q3 = c_kv/rho_A = 2·0.1·√(EI/rho_A) at the truth (c_kv = 2·0.1·√(67·23000) N·m²·s) and
// 2·0.06·√(19000/63) at the start (c_kv = 2·0.06·√(63·19000)), written to 17 digits.
#include "scoleid/io/builtin.h"

namespace scoleid::io {

std::vector<BuiltinScenario> beam_builtin_scenarios() {
  return {
      {"paper-beam-1",
       "Paper Case I: simply supported beam, step load and sensor at midspan; q1 = EI/rho_A, q2 = 1/rho_A",
       R"(name: paper-beam-1
description: "Paper Case I: simply supported beam, step load and sensor at midspan"
structure: beam
beam: {length: 10, left: pinned, right: pinned, rho_A: 67, EI: 23000, zeta: 0}
inputs:
  - {name: P, at: beam, kind: force, location: 5, unit: N, signal: {type: step, amplitude: 10, t0: 0}}
sensors:
  - {name: w_mid, at: beam, kind: displacement, location: 5, unit: m}
simulation: {duration: 10, sample_interval: 0.01, seed: 1}
identification:
  parameterization: paper
  estimate: [q1, q2]
  initial: {rho_A: 63, EI: 19000}
  elements: 10
truth: {segments: 40}
)"},
      {"paper-beam-2",
       "Paper Case II: Kelvin-Voigt damped cantilever, step load and sensor at the tip; q1, q2, q3 = c_kv/rho_A",
       R"(name: paper-beam-2
description: "Paper Case II: Kelvin-Voigt damped cantilever, step load and sensor at the tip"
structure: beam
beam: {length: 10, left: clamped, right: free, rho_A: 67, EI: 23000, zeta: 0, c_kv: 248.27404213892362}
inputs:
  - {name: P, at: beam, kind: force, location: 10, unit: N, signal: {type: step, amplitude: 10, t0: 0}}
sensors:
  - {name: w_tip, at: beam, kind: displacement, location: 10, unit: m}
simulation: {duration: 10, sample_interval: 0.01, seed: 1}
identification:
  parameterization: paper
  estimate: [q1, q2, q3]
  initial: {rho_A: 63, EI: 19000, c_kv: 131.28899420743537}
  elements: 10
truth: {segments: 40}
)"},
      {"paper-beam-3",
       "Paper Case III: simply supported beam with EI piecewise constant on two halves, rho_A known; sensors at L/4 and 3L/4",
       R"(name: paper-beam-3
description: "Paper Case III: simply supported beam, EI on two halves, sensors at L/4 and 3L/4"
structure: beam
beam: {length: 10, left: pinned, right: pinned, rho_A: 67, EI: [23000, 40000], zeta: 0}
inputs:
  - {name: P, at: beam, kind: force, location: 5, unit: N, signal: {type: step, amplitude: 10, t0: 0}}
sensors:
  - {name: w_q1, at: beam, kind: displacement, location: 2.5, unit: m}
  - {name: w_q3, at: beam, kind: displacement, location: 7.5, unit: m}
simulation: {duration: 10, sample_interval: 0.01, seed: 1}
identification:
  parameterization: physical
  estimate: [EI_1, EI_2]
  initial: {EI_1: 21000, EI_2: 39000}
  elements: 20
truth: {segments: 40}
)"},
      {"beam-ei8",
       "EI(x) on 8 sections of a simply supported beam, 8 displacement sensors, two loads; rho_A known",
       R"(name: beam-ei8
description: "EI(x) on 8 sections, 8 sensors at the section centres, step and pulse loads"
structure: beam
beam:
  length: 10
  left: pinned
  right: pinned
  rho_A: 67
  EI: [23000, 26000, 30000, 34000, 38000, 33000, 28000, 25000]
inputs:
  - {name: P1, at: beam, kind: force, location: 3.1, unit: N, signal: {type: step, amplitude: 10, t0: 0}}
  - {name: P2, at: beam, kind: force, location: 6.7, unit: N, signal: {type: haversine, amplitude: 20, t0: 0.5, width: 0.2}}
sensors:
  - {name: w1, location: 0.625, unit: m}
  - {name: w2, location: 1.875, unit: m}
  - {name: w3, location: 3.125, unit: m}
  - {name: w4, location: 4.375, unit: m}
  - {name: w5, location: 5.625, unit: m}
  - {name: w6, location: 6.875, unit: m}
  - {name: w7, location: 8.125, unit: m}
  - {name: w8, location: 9.375, unit: m}
simulation: {duration: 10, sample_interval: 0.01, seed: 1}
identification:
  parameterization: physical
  estimate: [EI_1, EI_2, EI_3, EI_4, EI_5, EI_6, EI_7, EI_8]
  initial: {EI: 30000}
  elements: 32
truth: {segments: 64}
)"},
  };
}

}  // namespace scoleid::io
