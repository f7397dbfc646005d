// The beam's gauges, each a row on u like a displacement sensor's, so their costate forcing and
// gradient need nothing new:
// - the strain gauge (kind: strain): ε = −offset · w_ss, the Hermite curvature row;
// - the relative-displacement gauge (kind: relative_displacement): w(location) − w(reference), the
//   difference of two Hermite displacement rows.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include <Eigen/SparseCholesky>
#include <nlohmann/json.hpp>

#include "test_support.h"
#include "scoleid/identify/fe/beam_model.h"
#include "scoleid/io/error.h"
#include "common/test_data.h"

using namespace scoleid::identify;
using test_support::Case;
using test_support::make_case;

namespace {

// A clamped aluminium strip (0.6 m, 3 mm thick: gauges 1.5 mm from the neutral axis), tapped near
// the tip; one displacement sensor beside two strain gauges.
const std::string kStrip = scoleid::test::test_scenario("strain_sensor_test/strain-strip");
// The same strip read by two relative-displacement gauges.
const std::string kGaugeStrip = scoleid::test::test_scenario("strain_sensor_test/gauge-strip");

// A tip load P on a clamped–free beam of length L and stiffness EI bends it into the cubic
// w(s) = P s² (3L − s) / (6 EI), M(s) = P (L − s), which Hermite cubics reproduce exactly: each
// gauge's reading on 3 elements must be `expected` (of the gauge) within `tolerance`.
constexpr double kP = 7.0, kL = 2.0, kEI = 500.0;
void expect_static_cantilever_readings(const std::vector<scoleid::io::SensorSpec>& gauges,
                                       const std::function<double(const scoleid::io::SensorSpec&)>& expected,
                                       double tolerance) {
  scoleid::io::BeamSpec beam;
  beam.length = kL;
  beam.left = scoleid::io::EndCondition::Clamped;
  beam.right = scoleid::io::EndCondition::Free;
  beam.rho_A = 1.0;
  beam.EI = {kEI};
  scoleid::io::InputSpec tip;
  tip.name = "P";
  tip.location = beam.length;
  const BeamFE fe = build_beam(beam, 3, 1, {tip}, gauges);
  const AssembledModel a = assemble(fe.model, beam_coefficients(fe, beam.rho_A, beam.EI, 0.0));
  Eigen::SimplicialLDLT<SparseMatrix> K(a.K);
  const VectorXd u = K.solve(kP * fe.model.inputs[0].vector);
  for (std::size_t k = 0; k < gauges.size(); ++k) {
    const double want = expected(gauges[k]), got = fe.model.sensors[k].row.dot(u);
    std::printf("  s = %.2f: %+.15e, expected %+.15e\n", gauges[k].location, got, want);
    EXPECT_NEAR(got, want, tolerance) << "s = " << gauges[k].location;
  }
}

scoleid::io::SensorSpec gauge(scoleid::io::SensorKind kind, double s, const char* field, double value) {
  scoleid::io::SensorSpec g;
  g.name = "g";
  g.kind = kind;
  g.location = s;
  g.fields[field] = value;
  return g;
}

// The costate gradient against central differences, and the Taylor remainder's second order.
void expect_exact_gradient(const std::string& yaml) {
  Case e = make_case(yaml, false);
  const VectorXd q = e.p->params->initial();
  test_support::expect_gradients_match_differences(*e.obj, q);
  const std::vector<double> R = test_support::taylor_remainders(*e.obj, q, 5);
  for (std::size_t k = 1; k < 5; ++k) {
    std::printf("  halving %zu: remainder ratio %.3f\n", k, R[k - 1] / R[k]);
    EXPECT_GT(R[k - 1] / R[k], 3.5) << "halving " << k;
    EXPECT_LT(R[k - 1] / R[k], 4.5) << "halving " << k;
  }
}

std::string error_of(const std::string& yaml) {
  try {
    scoleid::io::parse_scenario(yaml, "scenario 'g.yaml'");
  } catch (const scoleid::io::InputError& e) {
    return std::string(e.what());
  }
  return std::string();
}

}  // namespace

TEST(StrainSensor, TheHermiteCantileverReadsTheStaticMomentExactly) {
  // ε(s) = −c M(s) / EI = −c P (L − s) / EI to rounding at any s (the curvature row).
  const double c = 0.01;
  std::vector<scoleid::io::SensorSpec> gauges;
  for (double s : {0.0, 0.13, 0.5, 0.77, 1.0, 1.61, 2.0})
    gauges.push_back(gauge(scoleid::io::SensorKind::Strain, s, "offset", c));
  expect_static_cantilever_readings(
      gauges, [&](const scoleid::io::SensorSpec& g) { return -c * kP * (kL - g.location) / kEI; },
      1e-12 * c * kP * kL / kEI);
}

TEST(StrainSensor, GradientMatchesCentralDifferencesAndTheTaylorRemainderFallsAtSecondOrder) {
  expect_exact_gradient(kStrip);
}

TEST(StrainSensor, TheScenarioStatesTheGaugesOffsetAndNothingElseTakesOne) {
  const std::string head = "beam: {left: clamped, right: free}\ninputs: [{name: F, location: 10}]\n";
  const auto sc = scoleid::io::parse_scenario(head + "sensors: [{name: e, kind: strain, location: 1, offset: -0.002}]\n", "x");
  EXPECT_EQ(sc.sensors[0].field("offset"), -0.002);
  EXPECT_EQ(scoleid::io::to_json(sc)["sensors"][0]["offset"].get<double>(), -0.002);
  EXPECT_NE(error_of(head + "sensors: [{name: e, kind: strain, location: 1}]\n").find("sensors[0].offset"), std::string::npos);
  EXPECT_NE(error_of(head + "sensors: [{name: e, kind: strain, location: 1, offset: 0}]\n").find("must be nonzero"),
            std::string::npos);
  EXPECT_NE(error_of(head + "sensors: [{name: w, location: 1, offset: 0.01}]\n").find("belongs to strain gauges"),
            std::string::npos);
  const std::string scole = "structure: scole\ninputs: [{name: F, direction: y}]\n"
                            "sensors: [{name: e, at: mast, kind: strain, location: 10, offset: 0.1, direction: y}]\n";
  EXPECT_NE(error_of(scole).find("structure: beam"), std::string::npos) << error_of(scole);
}

TEST(RelativeDisplacement, TheHermiteCantileverReadsTheStaticDeflectionDifferenceExactly) {
  // Every gauge reads w(s) − w(r) to rounding, wherever its two ends fall in the elements.
  auto w = [](double s) { return kP * s * s * (3.0 * kL - s) / (6.0 * kEI); };
  std::vector<scoleid::io::SensorSpec> gauges;
  for (auto [s, r] :
       std::vector<std::pair<double, double>>{{2.0, 0.0}, {0.13, 0.5}, {0.77, 1.61}, {2.0, 1.0}, {1.61, 0.3}})
    gauges.push_back(gauge(scoleid::io::SensorKind::RelativeDisplacement, s, "reference", r));
  expect_static_cantilever_readings(
      gauges, [&](const scoleid::io::SensorSpec& g) { return w(g.location) - w(g.field("reference")); }, 1e-12 * w(kL));
}

TEST(RelativeDisplacement, GradientMatchesCentralDifferencesAndTheTaylorRemainderFallsAtSecondOrder) {
  expect_exact_gradient(kGaugeStrip);
}

TEST(RelativeDisplacement, TheScenarioStatesTheReferenceStationAndNothingElseTakesOne) {
  const std::string head = "beam: {length: 2, left: clamped, right: free}\ninputs: [{name: F, location: 2}]\n";
  const auto sc = scoleid::io::parse_scenario(
      head + "sensors: [{name: d, kind: relative_displacement, location: 2, reference: 0.5, unit: mm}]\n", "x");
  EXPECT_EQ(sc.sensors[0].field("reference"), 0.5);
  EXPECT_EQ(scoleid::io::to_json(sc)["sensors"][0]["reference"].get<double>(), 0.5);
  const std::string missing = error_of(head + "sensors: [{name: d, kind: relative_displacement, location: 1}]\n");
  EXPECT_NE(missing.find("sensors[0].reference"), std::string::npos) << missing;
  const std::string off =
      error_of(head + "sensors: [{name: d, kind: relative_displacement, location: 1, reference: 2.5}]\n");
  EXPECT_NE(off.find("sensors[0].reference"), std::string::npos) << off;
  EXPECT_NE(off.find("must lie on the beam"), std::string::npos) << off;
  const std::string same =
      error_of(head + "sensors: [{name: d, kind: relative_displacement, location: 1, reference: 1}]\n");
  EXPECT_NE(same.find("must differ from location"), std::string::npos) << same;
  const std::string stray = error_of(head + "sensors: [{name: w, location: 1, reference: 0.5}]\n");
  EXPECT_NE(stray.find("belongs to relative-displacement gauges"), std::string::npos) << stray;
  const std::string unit =
      error_of(head + "sensors: [{name: d, kind: relative_displacement, location: 1, reference: 0.5, unit: g}]\n");
  EXPECT_NE(unit.find("must be a unit of length"), std::string::npos) << unit;
  const std::string scole =
      "structure: scole\ninputs: [{name: F, direction: y}]\n"
      "sensors: [{name: d, at: mast, kind: relative_displacement, location: 10, reference: 5, direction: y}]\n";
  EXPECT_NE(error_of(scole).find("structure: beam"), std::string::npos) << error_of(scole);
}
