// The relative-displacement gauge (kind: relative_displacement): y = w(location) − w(reference),
// the difference of two Hermite displacement rows; its costate forcing and gradient come from the
// output row as a displacement sensor's do.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

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

// A clamped strip (0.6 m) tapped near the tip, read by two gauges between stations.
const std::string kStrip = scoleid::test::test_scenario("relative_displacement_test/gauge-strip");

std::string error_of(const std::string& yaml) {
  try {
    scoleid::io::parse_scenario(yaml, "scenario 'g.yaml'");
  } catch (const scoleid::io::InputError& e) {
    return std::string(e.what());
  }
  return std::string();
}

}  // namespace

TEST(RelativeDisplacement, TheHermiteCantileverReadsTheStaticDeflectionDifferenceExactly) {
  // A tip load P on a clamped–free beam bends it into the cubic w(s) = P s² (3L − s) / (6 EI),
  // which Hermite cubics reproduce exactly: every gauge reads w(s) − w(r) to rounding, wherever
  // its two ends fall in the elements.
  scoleid::io::BeamSpec beam;
  beam.length = 2.0;
  beam.left = scoleid::io::EndCondition::Clamped;
  beam.right = scoleid::io::EndCondition::Free;
  beam.rho_A = 1.0;
  beam.EI = {500.0};
  scoleid::io::InputSpec tip;
  tip.name = "P";
  tip.location = beam.length;
  const double P = 7.0;
  auto w = [&](double s) { return P * s * s * (3.0 * beam.length - s) / (6.0 * beam.EI[0]); };
  std::vector<scoleid::io::SensorSpec> gauges;
  for (auto [s, r] : std::vector<std::pair<double, double>>{{2.0, 0.0}, {0.13, 0.5}, {0.77, 1.61}, {2.0, 1.0}, {1.61, 0.3}}) {
    scoleid::io::SensorSpec g;
    g.name = "d";
    g.kind = scoleid::io::SensorKind::RelativeDisplacement;
    g.location = s;
    g.fields["reference"] = r;
    gauges.push_back(g);
  }
  const BeamFE fe = build_beam(beam, 3, 1, {tip}, gauges, "test");
  const AssembledModel a = assemble(fe.model, beam_coefficients(fe, beam.rho_A, beam.EI, 0.0));
  Eigen::SimplicialLDLT<SparseMatrix> K(a.K);
  const VectorXd u = K.solve(P * fe.model.inputs[0].vector);
  for (std::size_t k = 0; k < gauges.size(); ++k) {
    const double s = gauges[k].location, r = gauges[k].field("reference"), expected = w(s) - w(r);
    const double got = fe.model.sensors[k].row.dot(u);
    std::printf("  s = %.2f, reference %.2f: %+.15e, w(s) - w(r) %+.15e\n", s, r, got, expected);
    EXPECT_NEAR(got, expected, 1e-12 * w(beam.length)) << "s = " << s << ", reference " << r;
  }
}

TEST(RelativeDisplacement, GradientMatchesCentralDifferencesAndTheTaylorRemainderFallsAtSecondOrder) {
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

TEST(RelativeDisplacement, TheScenarioStatesTheReferenceStationAndNothingElseTakesOne) {
  const std::string head = "beam: {length: 2, left: clamped, right: free}\ninputs: [{name: F, location: 2}]\n";
  const auto sc = scoleid::io::parse_scenario(
      head + "sensors: [{name: d, kind: relative_displacement, location: 2, reference: 0.5, unit: mm}]\n", "x");
  EXPECT_EQ(sc.sensors[0].field("reference"), 0.5);
  EXPECT_EQ(scoleid::io::to_json(sc)["sensors"][0]["reference"].get<double>(), 0.5);
  const std::string missing = error_of(head + "sensors: [{name: d, kind: relative_displacement, location: 1}]\n");
  EXPECT_NE(missing.find("sensors[0].reference"), std::string::npos) << missing;
  const std::string off = error_of(head + "sensors: [{name: d, kind: relative_displacement, location: 1, reference: 2.5}]\n");
  EXPECT_NE(off.find("sensors[0].reference"), std::string::npos) << off;
  EXPECT_NE(off.find("must lie on the beam"), std::string::npos) << off;
  const std::string same = error_of(head + "sensors: [{name: d, kind: relative_displacement, location: 1, reference: 1}]\n");
  EXPECT_NE(same.find("must differ from location"), std::string::npos) << same;
  const std::string stray = error_of(head + "sensors: [{name: w, location: 1, reference: 0.5}]\n");
  EXPECT_NE(stray.find("belongs to relative-displacement gauges"), std::string::npos) << stray;
  const std::string unit = error_of(head + "sensors: [{name: d, kind: relative_displacement, location: 1, reference: 0.5, unit: g}]\n");
  EXPECT_NE(unit.find("must be a unit of length"), std::string::npos) << unit;
  const std::string scole = "structure: scole\ninputs: [{name: F, direction: y}]\n"
                            "sensors: [{name: d, at: mast, kind: relative_displacement, location: 10, reference: 5, direction: y}]\n";
  EXPECT_NE(error_of(scole).find("structure: beam"), std::string::npos) << error_of(scole);
}
