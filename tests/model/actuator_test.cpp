// Proof-mass actuators as hardware (docs/theory.md §3.7): a centering spring k_a and a damper
// c_a between the proof mass and the mast, in the Simbody chain.
//
// Single-DOF check. With the rest of SCOLE a million times heavier than the proof mass (every
// mass and stiffness scaled together, so its own modes stay where they are), the mast is a fixed
// base for the actuator: a commanded force F sin(ω t) on the proof mass gives the stroke
// r = ξ − u(s_k) the steady amplitude F / |k − m ω² + i c ω|, and at the actuator's resonance
// ω_a = √(k/m) exactly F / (c ω_a). The base's own motion enters at the mass ratio (1e-7).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "scoleid/io/scenario.h"
#include "scoleid/model/truth_run.h"

using namespace scoleid;
using namespace scoleid::model;

namespace {

double steady_stroke_amplitude(double frequency_hz, double k, double c, double F) {
  char text[2048];
  std::snprintf(text, sizeof text, R"(name: actuator-resonance
structure: scole
scole:
  rho_A: 95600
  EI: 4.0e13
  GJ: 4.0e13
  rho_I_psi: 908900
  shuttle: {mass: 6.366e9, Ixx: 9.05443e11, Iyy: 6.7891e12, Izz: 7.086601e12}
  reflector: {mass: 1.242e7, Ixx: 4.969e9, Iyy: 4.969e9, Izz: 9.938e9}
  actuator_mass: 0.2
  actuator_stiffness: %.17g
  actuator_damping: %.17g
  actuator_stroke: 1
inputs:
  - {name: a1x, at: actuator1, kind: force, direction: x, signal: {type: sine, amplitude: %.17g, frequency: %.17g}}
)",
                k, c, F, frequency_hz);
  const auto sc = io::parse_scenario(text, "test");
  const auto st = prepare_structure(sc, 10);
  const auto& system = st->system();
  SimTK::State s = system.getDefaultState();
  const auto& slider = st->matter().getMobilizedBody(st->actuator_slider(1, 0));
  SimulateOptions o;
  o.integrator = "rk-merson";
  o.accuracy = 1e-9;
  o.final_time = 14.0;
  o.sample_interval = 5e-4;
  double amplitude = 0.0;
  simulate(system, s, o, [&](const SimTK::State& x) {
    // Transients decay as exp(−ζ_a ω_a t), ζ_a = 0.05: below 1e-5 after 12 s.
    if (x.getTime() >= 12.0) amplitude = std::max(amplitude, std::abs(slider.getOneQ(x, 0)));
  });
  return amplitude;
}

}  // namespace

TEST(ProofMassActuator, ResonanceAmplitudeIsForceOverDampingTimesFrequency) {
  const double m = 0.2, f = 3.0, w = 2 * M_PI * f;  // between the structure's modes 5 and 6
  const double k = m * w * w, c = 2 * 0.05 * m * w, F = 0.1;
  const double expected = F / (c * w);
  const double got = steady_stroke_amplitude(f, k, c, F);
  std::printf("  k_a %.4f lb/ft, c_a %.5f lb s/ft, resonance %.3f Hz: stroke amplitude %.6e ft, F/(c w) %.6e ft (%+.2e)\n",
              k, c, f, got, expected, got / expected - 1.0);
  // Sampling at 0.5 ms reads a peak low by at most (ω Δt)²/8 = 1e-5.
  EXPECT_NEAR(got / expected, 1.0, 2e-4);
  // Off resonance (1.5 ω_a) the full single-DOF law.
  const double f2 = 1.5 * f, w2 = 2 * M_PI * f2;
  const double expected2 = F / std::hypot(k - m * w2 * w2, c * w2);
  const double got2 = steady_stroke_amplitude(f2, k, c, F);
  std::printf("  at %.3f Hz: %.6e ft against %.6e ft (%+.2e)\n", f2, got2, expected2, got2 / expected2 - 1.0);
  EXPECT_NEAR(got2 / expected2, 1.0, 2e-4);
}
