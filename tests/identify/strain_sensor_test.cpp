// The strain gauge (kind: strain): ε = −offset · w_ss, the Hermite curvature row; its costate
// forcing and gradient come from the same output row as a displacement sensor's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <Eigen/SparseCholesky>

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

}  // namespace

TEST(StrainSensor, TheHermiteCantileverReadsTheStaticMomentExactly) {
  // A tip load P on a clamped–free beam: M(s) = P (L − s), a cubic deflection that Hermite cubics
  // reproduce exactly, so the curvature row gives ε(s) = −c P (L − s) / EI to rounding at any s.
  scoleid::io::BeamSpec beam;
  beam.length = 2.0;
  beam.left = scoleid::io::EndCondition::Clamped;
  beam.right = scoleid::io::EndCondition::Free;
  beam.rho_A = 1.0;
  beam.EI = {500.0};
  scoleid::io::InputSpec tip;
  tip.name = "P";
  tip.location = beam.length;
  std::vector<scoleid::io::SensorSpec> gauges;
  const double c = 0.01, P = 7.0;
  for (double s : {0.0, 0.13, 0.5, 0.77, 1.0, 1.61, 2.0}) {
    scoleid::io::SensorSpec g;
    g.name = "eps";
    g.kind = scoleid::io::SensorKind::Strain;
    g.location = s;
    g.fields["offset"] = c;
    gauges.push_back(g);
  }
  const BeamFE fe = build_beam(beam, 3, 1, {tip}, gauges, "test");
  const AssembledModel a = assemble(fe.model, beam_coefficients(fe, beam.rho_A, beam.EI, 0.0));
  Eigen::SimplicialLDLT<SparseMatrix> K(a.K);
  const VectorXd u = K.solve(P * fe.model.inputs[0].vector);
  for (std::size_t k = 0; k < gauges.size(); ++k) {
    const double s = gauges[k].location, expected = -c * P * (beam.length - s) / beam.EI[0];
    const double got = fe.model.sensors[k].row.dot(u);
    std::printf("  s = %.2f: strain %+.15e, -c P (L - s) / EI %+.15e\n", s, got, expected);
    EXPECT_NEAR(got, expected, 1e-12 * c * P * beam.length / beam.EI[0]) << "s = " << s;
  }
}

TEST(StrainSensor, GradientMatchesCentralDifferencesAndTheTaylorRemainderFallsAtSecondOrder) {
  Case e = make_case(kStrip, false);
  const VectorXd q = e.p->params->initial();
  test_support::expect_gradients_match_differences(*e.obj, q);
  const std::vector<double> R = test_support::taylor_remainders(*e.obj, q, 5);
  for (std::size_t k = 1; k < 5; ++k) {
    std::printf("  halving %zu: remainder ratio %.3f\n", k, R[k - 1] / R[k]);
    EXPECT_GT(R[k - 1] / R[k], 3.5) << "halving " << k;
    EXPECT_LT(R[k - 1] / R[k], 4.5) << "halving " << k;
  }
}

TEST(StrainSensor, TheScenarioStatesTheGaugesOffsetAndNothingElseTakesOne) {
  auto error_of = [](const std::string& yaml) {
    try {
      scoleid::io::parse_scenario(yaml, "scenario 'g.yaml'");
    } catch (const scoleid::io::InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
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
