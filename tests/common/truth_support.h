#pragma once
// The Simbody truth as the crosscheck tests that identify from it simulate it.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "scoleid/truth.h"

namespace scoleid::test {

// These tests hold an identification from the truth to 1e-3 and coarser. The truth's default
// accuracy (1e-9, the energy-drift criterion of docs/theory.md §9.5) puts the fixed-step
// integrators' frequency error near 1e-9 at the fastest mode the inputs excite, and costs these
// tests most of their time. At 1e-5 the error is about 1e-5 there ((ωh)⁴/720 for Gauss–Legendre,
// (ωh)²/12 for the trapezoidal rule) and smaller on every slower mode: two orders below the
// tightest figure asserted, while the step is 6× (Gauss–Legendre) longer.
inline constexpr double kIdentificationTruthAccuracy = 1e-5;

// The truth of `scenario` at kIdentificationTruthAccuracy. Only for unconstrained chains, whose
// integrator is a fixed-step one with this accuracy's meaning: Simbody's error-controlled
// integrators (constrained chains) keep the scenario's own accuracy.
inline Truth identification_truth(const io::Scenario& scenario) {
  TruthOptions options;
  options.accuracy = kIdentificationTruthAccuracy;
  Truth truth = simulate_truth(scenario, options);
  const std::string& integrator = truth.summary.integrator;
  EXPECT_TRUE(integrator == "gauss-legendre" || integrator == "trapezoidal")
      << scenario.name << ": integrated by " << integrator << ", whose accuracy is a local error bound, not a frequency error";
  return truth;
}

}  // namespace scoleid::test
