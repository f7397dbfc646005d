// The built-in 20 deg roll slew (scole-slew): a rest-to-rest bang-bang roll moment of amplitude
// A and width w on the free-floating SCOLE. Rigid-body prediction: theta(w) = A w^2 / (4 I_c,xx),
// I_c the whole system's central inertia, for the rigid-body mode, about which the shuttle's roll
// oscillates once the moment stops (time average after the slew). From then on no external load
// acts: the angular momentum about the system CM is constant (it is not zero: the moment is fixed
// in the shuttle, which the flexible, offset reflector makes wobble in pitch and yaw during the
// slew, so the impulses of the two halves do not cancel exactly).
// The nonlinear coupling shows as the departure of the 20 deg response from 100 x the response
// to the same slew scaled down to 0.2 deg (which a linear model would reproduce exactly).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scoleid/io/scenario.h"
#include "scoleid/model/sensors.h"
#include "scoleid/model/truth_run.h"

using namespace scoleid;
using namespace scoleid::model;

namespace {

struct SlewRun {
  std::vector<double> t, roll, tip;  // shuttle roll angle, mast-tip roll displacement (shuttle y)
  double H_peak = 0.0, H_after = 0.0;  // |angular momentum about the system CM|
  double H_drift = 0.0;                // max |H_c(t) - H_c(w)| for t >= w
  double I_xx = 0.0;
};

SlewRun slew(const io::Scenario& sc, int n) {
  const auto st = prepare_structure(sc, n);
  const auto sensors = resolve_sensors(sc, *st);
  const auto& sys = st->system();
  SimulateOptions o;
  o.integrator = "rk-merson";
  o.accuracy = 1e-8;
  o.final_time = sc.simulation.duration;
  o.sample_interval = 0.05;
  for (const auto& in : sc.inputs)
    for (double b : in.signal.breakpoints()) o.breakpoints.push_back(b);
  const double w = sc.inputs[0].signal.terms()[0].width;
  SlewRun r;
  SimTK::Vec3 H_end(0);
  const SimTK::State s0 = sys.getDefaultState();
  sys.realize(s0, SimTK::Stage::Position);
  r.I_xx = st->matter().calcSystemCentralInertiaInGround(s0).getMoments()[0];
  simulate(sys, s0, o, [&](const SimTK::State& s) {
    r.t.push_back(s.getTime());
    r.roll.push_back(read_sensor(st->matter(), s, sensors[0]));
    r.tip.push_back(read_sensor(st->matter(), s, sensors[1]));
    const SimTK::Vec3 Hv = st->matter().calcSystemCentralMomentum(s)[0];
    r.H_peak = std::max(r.H_peak, Hv.norm());
    if (s.getTime() >= w - 1e-9) {
      if (r.H_after == 0.0) H_end = Hv;
      r.H_after = std::max(r.H_after, Hv.norm());
      r.H_drift = std::max(r.H_drift, (Hv - H_end).norm());
    }
  });
  return r;
}

}  // namespace

TEST(ScoleSlew, TwentyDegreeRestToRestRollSlew) {
  const io::Scenario sc = io::load_scenario("scole-slew");
  ASSERT_EQ(sc.sensors[0].name, "roll");
  ASSERT_EQ(sc.sensors[1].name, "roll_tip");
  const auto& bang = sc.inputs[0].signal.terms()[0];
  const int n = 10;
  const SlewRun big = slew(sc, n);
  const double theta_rigid = bang.amplitude * bang.width * bang.width / (4 * big.I_xx);
  const std::size_t k_end = static_cast<std::size_t>(std::lround(bang.width / 0.05));
  double mean = 0.0;
  int count = 0;
  for (std::size_t i = k_end; i < big.roll.size(); ++i, ++count) mean += big.roll[i];
  mean /= count;
  std::printf("I_c,xx = %.6e slug ft^2; rigid slew %.4f deg; shuttle roll at t = w %.4f deg, mean after %.4f deg\n",
              big.I_xx, theta_rigid * 180 / SimTK::Pi, big.roll[k_end] * 180 / SimTK::Pi, mean * 180 / SimTK::Pi);
  EXPECT_NEAR(theta_rigid * 180 / SimTK::Pi, 20.0, 0.01);   // the scenario's amplitude is the 20 deg slew
  EXPECT_NEAR(mean / theta_rigid, 1.0, 0.005);
  std::printf("|H_c| peak %.4e, after the slew %.4e (relative %.2e), change after the slew %.2e relative\n",
              big.H_peak, big.H_after, big.H_after / big.H_peak, big.H_drift / big.H_peak);
  EXPECT_LT(big.H_drift, 1e-7 * big.H_peak);

  io::Scenario small = sc;
  small.inputs[0].signal = io::Signal({[&] { auto t = bang; t.amplitude /= 100; return t; }()});
  const SlewRun lin = slew(small, n);
  double tip_max = 0, diff = 0, resid = 0;
  for (std::size_t i = 0; i < big.tip.size(); ++i) {
    tip_max = std::max(tip_max, std::abs(big.tip[i]));
    diff = std::max(diff, std::abs(big.tip[i] - 100 * lin.tip[i]));
    if (big.t[i] > bang.width) resid = std::max(resid, std::abs(big.tip[i]));
  }
  std::printf("mast-tip roll displacement: max %.4e ft, residual after slew %.4e ft; "
              "departure from linear scaling %.3e (relative %.2e)\n", tip_max, resid, diff, diff / tip_max);
  EXPECT_GT(resid, 1e-3 * tip_max);  // the slew leaves the mast vibrating
  EXPECT_GT(diff / tip_max, 1e-3);   // and the 20 deg response is measurably nonlinear
}
