// The implicit fixed-step methods of the Simbody truth, the trapezoidal rule (model/trapezoidal.h)
// and two-stage Gauss–Legendre collocation (model/gauss_legendre.h):
//  - their order: on SCOLE under the paper's reflector pulses, the trajectory error against a
//    tight reference falls by 4 (trapezoidal) and 16 (Gauss–Legendre) per halving of the step;
//  - at the default step rule their error is far below the chain's lumping error, at fewer
//    evaluations than RK-Merson; Gauss–Legendre's is also far below the trapezoidal rule's, at
//    fewer evaluations;
//  - a constrained chain is refused (no projection onto constraints);
//  - Gauss–Legendre realizes its step ends only as far as the sampler reads, bit for bit the same,
//    and takes a step whose Newton iteration fails as two halves.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "scoleid/io/scenario.h"
#include "scoleid/model/gauss_legendre.h"
#include "scoleid/model/sensors.h"
#include "scoleid/model/trapezoidal.h"
#include "scoleid/model/truth_run.h"
#include "test_support.h"

using namespace scoleid;
using namespace scoleid::model;

namespace {

using Traj = std::vector<std::vector<double>>;   // [sensor][sample]

Traj run(const io::Scenario& sc, const Structure& st, const std::string& integrator, double accuracy, double max_step,
         SimulateSummary* summary = nullptr, SimTK::Stage sample_stage = SimTK::Stage::Acceleration) {
  const auto sensors = resolve_sensors(sc, st);
  SimulateOptions o;
  o.integrator = integrator;
  o.accuracy = accuracy;
  o.max_step = max_step;
  o.final_time = sc.simulation.duration;
  o.sample_interval = sc.simulation.sample_interval;
  o.sample_stage = sample_stage;
  for (const auto& in : sc.inputs)
    for (double b : in.signal.breakpoints()) o.breakpoints.push_back(b);
  Traj y(sensors.size());
  const auto sum = simulate(st.system(), st.system().getDefaultState(), o, [&](const SimTK::State& s) {
    for (std::size_t j = 0; j < sensors.size(); ++j) y[j].push_back(read_sensor(st.matter(), s, sensors[j]));
  });
  if (summary) *summary = sum;
  return y;
}

// max over sensors of max_t |y - y_ref| / max_t |y_ref|
double error(const Traj& y, const Traj& ref) {
  double e = 0.0;
  for (std::size_t j = 0; j < ref.size(); ++j) {
    double scale = 0.0, d = 0.0;
    for (double v : ref[j]) scale = std::max(scale, std::abs(v));
    for (std::size_t i = 0; i < ref[j].size(); ++i) d = std::max(d, std::abs(y[j].at(i) - ref[j][i]));
    e = std::max(e, d / scale);
  }
  return e;
}

}  // namespace

TEST(Trapezoidal, SecondOrderOnScole) {
  io::Scenario sc = io::load_scenario("paper-scole-1");
  sc.simulation.duration = 4.0;
  sc.simulation.sample_interval = 0.02;
  const auto st = prepare_structure(sc, 10);
  const Traj ref = run(sc, *st, "rk-merson", 1e-11, 0.0);
  std::vector<double> e;
  for (double h : {0.02, 0.01, 0.005, 0.0025}) {
    e.push_back(error(run(sc, *st, "trapezoidal", 1e-12, h), ref));
    std::printf("trapezoidal h = %.4f s: trajectory error %.3e%s\n", h, e.back(),
                e.size() > 1 ? (" rate " + std::to_string(std::log2(e[e.size() - 2] / e.back()))).c_str() : "");
  }
  for (std::size_t i = 1; i < e.size(); ++i) EXPECT_NEAR(std::log2(e[i - 1] / e[i]), 2.0, 0.15) << i;
}

// At the default step rule (accuracy 1e-9 on the fundamental mode) the time-discretisation error
// must be small against what the truth is for: the chain's own lumping error, measured here as the
// trajectory difference between n and 2n segments. The trapezoidal rule must also be cheaper than
// RK-Merson at the same accuracy setting (fewer realizations of the multibody equations).
TEST(Trapezoidal, DefaultStepErrorFarBelowLumpingError) {
  io::Scenario sc = io::load_scenario("paper-scole-1");
  sc.simulation.duration = 4.0;
  sc.simulation.sample_interval = 0.01;
  const auto st = prepare_structure(sc, 10);
  const auto st2 = prepare_structure(sc, 20);
  const Traj ref = run(sc, *st, "rk-merson", 1e-11, 0.0);
  const double lumping = error(ref, run(sc, *st2, "rk-merson", 1e-10, 0.0));
  SimulateSummary ts, rs;
  const double et = error(run(sc, *st, "trapezoidal", 1e-9, 0.0, &ts), ref);
  const double er = error(run(sc, *st, "rk-merson", 1e-9, 0.0, &rs), ref);
  std::printf("accuracy 1e-9: trapezoidal error %.3e (%d steps, %d realizations, step %.4g s), rk-merson %.3e (%d steps, "
              "%d realizations); lumping n = 10 vs 20: %.3e\n", et, ts.steps_taken, ts.realizations, ts.max_step, er,
              rs.steps_taken, rs.realizations, lumping);
  EXPECT_LT(et, 0.02 * lumping);
  EXPECT_LT(ts.realizations, rs.realizations);
}

TEST(Trapezoidal, RefusesConstrainedChains) {
  const auto sc = io::load_scenario("paper-beam-1");   // simply supported: pin + roller constraints
  const auto st = prepare_structure(sc, 10);
  EXPECT_THROW(TrapezoidalIntegrator(st->system(), st->system().getDefaultState()), std::invalid_argument);
  EXPECT_THROW(GaussLegendreIntegrator(st->system(), st->system().getDefaultState()), std::invalid_argument);
}

// Fourth order: the same SCOLE run at four steps against a reference of the same method at a
// step 16 times shorter than the shortest (whose own error is 16^4 times smaller), the error
// falling by 2^4 per halving (measured rates 3.86, 3.69, 4.04).
TEST(GaussLegendre, FourthOrderOnScole) {
  io::Scenario sc = io::load_scenario("paper-scole-1");
  sc.simulation.duration = 4.0;
  sc.simulation.sample_interval = 0.04;
  const auto st = prepare_structure(sc, 10);
  const Traj ref = run(sc, *st, "gauss-legendre", 1e-12, 0.005 / 16);
  std::vector<double> e;
  for (double h : {0.04, 0.02, 0.01, 0.005}) {
    e.push_back(error(run(sc, *st, "gauss-legendre", 1e-12, h), ref));
    std::printf("gauss-legendre h = %.4f s: trajectory error %.3e%s\n", h, e.back(),
                e.size() > 1 ? (" rate " + std::to_string(std::log2(e[e.size() - 2] / e.back()))).c_str() : "");
  }
  for (std::size_t i = 1; i < e.size(); ++i) EXPECT_NEAR(std::log2(e[i - 1] / e[i]), 4.0, 0.4) << i;
}

// At the default step rule (accuracy 1e-9: its step is then the sample interval) the method's error
// is far below the chain's lumping error and below the trapezoidal rule's at its default, and it
// costs fewer realizations than the trapezoidal rule.
TEST(GaussLegendre, DefaultStepMoreAccurateAndCheaperThanTrapezoidal) {
  io::Scenario sc = io::load_scenario("paper-scole-1");
  sc.simulation.duration = 4.0;
  sc.simulation.sample_interval = 0.01;
  const auto st = prepare_structure(sc, 10);
  const auto st2 = prepare_structure(sc, 20);
  const Traj ref = run(sc, *st, "rk-merson", 1e-12, 0.0);
  const double lumping = error(ref, run(sc, *st2, "rk-merson", 1e-10, 0.0));
  SimulateSummary gs, ts;
  const double eg = error(run(sc, *st, "gauss-legendre", 1e-9, 0.0, &gs), ref);
  const double et = error(run(sc, *st, "trapezoidal", 1e-9, 0.0, &ts), ref);
  std::printf("accuracy 1e-9: gauss-legendre error %.3e (%d steps, %d realizations, step %.4g s), trapezoidal %.3e (%d "
              "steps, %d realizations); lumping n = 10 vs 20: %.3e\n", eg, gs.steps_taken, gs.realizations, gs.max_step,
              et, ts.steps_taken, ts.realizations, lumping);
  EXPECT_LT(eg, 1e-3 * lumping);
  EXPECT_LT(eg, 0.1 * et);
  EXPECT_LT(gs.realizations, ts.realizations);
}

// A caller that reads positions and velocities only lets the method realize its step ends to
// Velocity: the same trajectory, bit for bit (the method's own arithmetic reads only its stages),
// in fewer accelerations.
TEST(GaussLegendre, StepEndsRealizedToVelocityGiveTheSameTrajectory) {
  io::Scenario sc = io::load_scenario("paper-scole-1");
  sc.simulation.duration = 2.0;
  const auto st = prepare_structure(sc, 10);
  const Traj a = run(sc, *st, "gauss-legendre", 1e-9, 0.0);
  const Traj v = run(sc, *st, "gauss-legendre", 1e-9, 0.0, nullptr, SimTK::Stage::Velocity);
  ASSERT_EQ(a.size(), v.size());
  for (std::size_t j = 0; j < a.size(); ++j) EXPECT_EQ(a[j], v[j]) << j;
}

// A step whose Newton iteration fails is taken as two halves: the spinning, deformed, undamped
// SCOLE at 0.4 s steps (its Jacobian turns with the spin, and the chain's top modes sit at
// omega h in the hundreds) fails some steps; the run completes by splitting them, and ends where a
// run at 0.05 s steps (no splits) ends, to within 1 % of the distance the spinning tip moved (the
// difference is the chain modes' phase error at omega h >> 1).
TEST(GaussLegendre, AStepWhoseNewtonIterationFailsIsTakenInHalves) {
  const auto sc = io::parse_scenario("name: energy-scole\nstructure: scole\nscole: {zeta: 0}\n", "test");
  const auto st = prepare_structure(sc, 10);
  SimTK::State s = st->system().getDefaultState();
  test::deform(*st, s, 0.002);
  const auto& shuttle = st->matter().getMobilizedBody(SimTK::MobilizedBodyIndex(1));
  shuttle.setUToFitAngularVelocity(s, SimTK::Vec3(0.01, -0.02, 0.015));
  auto run = [&](double h) {
    GaussLegendreOptions o;
    o.max_step = h;
    auto g = std::make_unique<GaussLegendreIntegrator>(st->system(), s, o);
    g->advance_to(4.0);
    return g;
  };
  const auto coarse = run(0.4), fine = run(0.05);
  const auto& tip = st->matter().getMobilizedBody(st->segment_bodies().back());
  const double d = (tip.getBodyOriginLocation(coarse->state()) - tip.getBodyOriginLocation(fine->state())).norm();
  st->system().realize(s, SimTK::Stage::Position);
  const double moved = (tip.getBodyOriginLocation(fine->state()) - tip.getBodyOriginLocation(s)).norm();
  std::printf("0.4 s steps: %d split, %d steps; 0.05 s steps: %d split; tip position difference %.3e ft, tip moved %.3e ft\n",
              coarse->summary().split_steps, coarse->summary().steps, fine->summary().split_steps, d, moved);
  EXPECT_GT(coarse->summary().split_steps, 0);
  EXPECT_EQ(fine->summary().split_steps, 0);
  EXPECT_LT(d, 1e-2 * moved);
}

// Quaternions (the shuttle's free joint): a free rigid body, turned to an arbitrary attitude,
// under a constant torque along one of its principal axes spins up about that fixed axis,
// theta(t) = M t^2 / (2 I). Its quaternion is not polynomial in t, so the angle error falls at
// the method's fourth order. (The stage equations q' = N(q) u must be solved in q itself: solved
// only within N's range, the quaternion's radial residual is left and the error is first order.)
TEST(GaussLegendre, RigidBodySpinUpAboutAPrincipalAxisIsFourthOrder) {
  using namespace SimTK;
  MultibodySystem system;
  SimbodyMatterSubsystem matter(system);
  GeneralForceSubsystem forces(system);
  const Vec3 inertia(2.0, 3.0, 5.0);
  const Body::Rigid body(MassProperties(7.0, Vec3(0), Inertia(inertia)));
  MobilizedBody::Free free(matter.Ground(), Transform(), body, Transform());
  const Rotation R0(BodyRotationSequence, 0.7, XAxis, -0.4, YAxis, 1.1, ZAxis);
  const double M = 3.0, T = 2.0;
  const UnitVec3 axis = R0 * UnitVec3(YAxis);   // the body's principal axis y (I = 3), in ground
  Force::ConstantTorque(forces, free, M * Vec3(axis));
  system.realizeTopology();
  State s = system.getDefaultState();
  free.setQToFitRotation(s, R0);
  auto angle_error = [&](double h) {
    GaussLegendreOptions o;
    o.max_step = h;
    GaussLegendreIntegrator g(system, s, o);
    g.advance_to(T);
    const Rotation turned = free.getBodyRotation(g.state()) * ~R0;   // ground: about `axis` by theta
    const Vec4 aa = turned.convertRotationToAngleAxis();
    const double theta = aa[0] * dot(Vec3(aa[1], aa[2], aa[3]), Vec3(axis));
    return std::abs(theta - M * T * T / (2.0 * inertia[1]));
  };
  const double e1 = angle_error(0.1), e2 = angle_error(0.05);
  std::printf("spin-up to %.3f rad: angle error %.3e at h = 0.1, %.3e at 0.05 (order %.2f)\n", M * T * T / (2.0 * inertia[1]),
              e1, e2, std::log2(e1 / e2));
  EXPECT_GT(std::log2(e1 / e2), 3.5);
  EXPECT_LT(e2, 1e-6);
}
