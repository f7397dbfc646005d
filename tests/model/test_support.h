#pragma once
// Helpers shared by the model tests: initial deformation, first period, energy drift.
#include <algorithm>
#include <cmath>
#include <string>

#include "scoleid/model/linearisation.h"
#include "scoleid/model/truth_run.h"

namespace scoleid::model::test {

using SimTK::State;

// Deforms the chain into the shape of a static tip load: joint j at s_j turns by
// amplitude * (1 - s_j / L) (the bending moment of a tip load, over a uniform joint stiffness).
inline void deform(const Structure& st, State& s, double amplitude) {
  const double h = st.length() / st.segments();
  const auto& bodies = st.segment_bodies();
  for (const auto& j : st.joint_springs()) {
    const auto it = std::find(bodies.begin(), bodies.end(), j.body);
    const double sj = it == bodies.end() ? st.length() : h * static_cast<double>(it - bodies.begin());
    st.matter().getMobilizedBody(j.body).setOneQ(s, j.which, amplitude * (1.0 - sj / st.length()) * (1 + 0.3 * j.which));
  }
}

inline double first_period(const Structure& st) {
  const auto modes = natural_modes(st.system(), st.system().getDefaultState());
  return 2 * SimTK::Pi / modes.at(0).omega;
}

inline double energy_drift(const Structure& st, const State& s0, double accuracy, double periods, int* steps,
                           const std::string& integrator = "rk-merson") {
  const auto& sys = st.system();
  sys.realize(s0, SimTK::Stage::Acceleration);
  const double E0 = sys.calcEnergy(s0);
  SimulateOptions o;
  o.integrator = integrator;
  o.accuracy = accuracy;
  const double T1 = first_period(st);
  o.final_time = periods * T1;
  o.sample_interval = T1 / 8;
  double drift = 0.0;
  const auto sum = simulate(sys, s0, o, [&](const State& s) { drift = std::max(drift, std::abs(sys.calcEnergy(s) / E0 - 1)); });
  *steps = sum.steps_taken;
  return drift;
}

}  // namespace scoleid::model::test
