// Energy of the undamped, unforced, free-floating SCOLE (spinning and deformed) is conserved:
// the drift over 50 periods of the first flexible mode measures the integrator. Slow (minutes):
// the spinning free body and the reflector's stiff end cell hold RK-Merson to ~0.1 ms steps.
#include <gtest/gtest.h>

#include <cstdio>

#include "scoleid/io/scenario.h"
#include "test_support.h"

using namespace scoleid;
using namespace scoleid::model;
using namespace scoleid::model::test;

TEST(ScoleEnergy, UndampedSpinningScoleOver50Periods) {
  const auto sc = io::parse_scenario("name: energy-scole\nstructure: scole\nscole: {zeta: 0}\n", "test");
  const auto st = prepare_structure(sc, 10);
  State s = st->system().getDefaultState();
  deform(*st, s, 0.002);
  const auto& shuttle = st->matter().getMobilizedBody(SimTK::MobilizedBodyIndex(1));
  shuttle.setUToFitAngularVelocity(s, SimTK::Vec3(0.01, -0.02, 0.015));
  int steps = 0;
  const double drift = energy_drift(*st, s, 1e-8, 50, &steps);
  std::printf("SCOLE n=10, rk-merson accuracy 1e-8: max |E/E0 - 1| over 50 periods = %.3e (%d steps)\n", drift, steps);
  EXPECT_LT(drift, 1e-6);
}
