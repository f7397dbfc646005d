// The beam's gauges across the gap, and EI, ρA and ζ identified from the chain's gauges through
// the front doors:
// - strain gauges: the Simbody chain's joint moments against the finite-element curvature row;
// - relative-displacement gauges: the chain's reading is the difference of its own displacement
//   read-outs at the two stations, and meets the finite-element one at second order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "scoleid/crosscheck/trajectories.h"
#include "scoleid/identify.h"
#include "scoleid/truth.h"
#include "common/test_data.h"

using namespace scoleid;

namespace {

// A clamped aluminium strip (0.6 m, EI 30 N·m², ρA 0.4 kg/m, 3 mm thick: gauges 1.5 mm from the
// neutral axis on either face), tapped near the tip with a 4 ms haversine, sampled at 2 kHz.
io::Scenario strip() {
  return io::parse_scenario(scoleid::test::test_scenario("strain_gauge_test/strain-strip"),
                            "strain strip");
}
// The same strip read by two relative-displacement gauges.
io::Scenario gauge_strip() {
  return io::parse_scenario(scoleid::test::test_scenario("strain_sensor_test/gauge-strip"), "gauge strip");
}

// The chain's readings converge onto the fine FE model's at second order in the segments: the
// relative RMS difference falls by about 4 per doubling (20, 40, 80 segments), below 1 % at 80.
void expect_second_order_convergence(const io::Scenario& sc, const std::string& dir_name) {
  crosscheck::TrajectoryOptions o;
  o.segments = 20;
  o.levels = 3;
  o.elements = 96;
  const auto dir = std::filesystem::temp_directory_path() / dir_name;
  std::filesystem::remove_all(dir);
  const auto r = crosscheck::compare_trajectories(sc, o, dir.string());
  for (const auto& s : r.sensors) {
    std::printf("  %-9s relative RMS", s.name.c_str());
    for (double e : s.relative_rms) std::printf(" %.3e", e);
    std::printf("  rate %.2f\n", s.rate);
    EXPECT_GT(s.rate, 1.7) << s.name;
    EXPECT_LT(s.rate, 2.5) << s.name;
    EXPECT_LT(s.relative_rms.back(), 1e-2) << s.name;
  }
  std::filesystem::remove_all(dir);
}

// The scenario's parameters identified from its 80-segment truth: EI and ρA within 1 %, ζ 5 %.
void expect_identified_from_the_truth(const io::Scenario& sc) {
  const Truth truth = simulate_truth(sc);
  const Identification id =
      identify_parameters(sc, DataSource::in_memory(truth.table, sc.name + " truth", truth.meta), {});
  std::printf("%s", id.FullReport().c_str());
  EXPECT_TRUE(id.converged()) << id.verdict();
  const auto& r = id.result();
  for (std::size_t i = 0; i < id.names().size(); ++i) {
    const std::string& n = id.names()[i];
    const double e = id.estimate()[static_cast<Eigen::Index>(i)] / r.truth.at(n) - 1.0;
    std::printf("  %-6s relative error %+.2e\n", n.c_str(), e);
    EXPECT_LT(std::abs(e), n == "zeta" ? 0.05 : 1e-2) << n;
  }
}

const std::vector<double>& column(const io::DataTable& t, const std::string& name) {
  const int c = t.find(name);
  EXPECT_GE(c, 0) << name;
  return t.columns.at(static_cast<std::size_t>(std::max(c, 0)));
}

}  // namespace

TEST(StrainGauge, TheChainsGaugesConvergeOntoTheFiniteElementCurvatureAtSecondOrder) {
  // The chain's joint moments are EI w_ss at the joints to O(h²), and the gauges read them linearly
  // between joints (measured: 4.8e-2, 1.2e-2, 3.2e-3 at the root gauge, 8.9e-2, 2.3e-2, 6.0e-3 at
  // midspan, for 20, 40 and 80 segments: rates 1.92 and 1.93).
  expect_second_order_convergence(strip(), "scoleid-strain-trajectories");
}

TEST(StrainGauge, EIRhoAAndZetaFromTwoGaugesOnTheEightySegmentTruth) { expect_identified_from_the_truth(strip()); }

TEST(StrainGauge, AGaugeAtACompliantClampReadsTheRootMoment) {
  // The end joint carries the clamp's spring in series with the end cell's (beam_chain.h): a gauge
  // inside the first segment reads k_θ w_s(0) at the root, converging like the clamped strip's.
  expect_second_order_convergence(
      io::parse_scenario(scoleid::test::test_scenario("strain_gauge_test/strain-compliant-clamp"), "compliant clamp"),
      "scoleid-strain-compliant-clamp");
}

TEST(RelativeDisplacementGauge, TheChainReadsTheDifferenceOfItsTwoStationsDisplacements) {
  // The same truth with displacement sensors at each gauge's two stations: a gauge must read
  // w(s) − w(r) of the chain to rounding (both read-outs are the same station positions).
  io::Scenario sc = gauge_strip();
  sc.simulation.duration = 0.05;
  const std::size_t gauges = sc.sensors.size();
  for (std::size_t k = 0; k < gauges; ++k) {
    for (const char* end : {"at", "ref"}) {
      io::SensorSpec w;
      w.name = sc.sensors[k].name + "_" + end;
      w.location = std::string(end) == "at" ? sc.sensors[k].location : sc.sensors[k].field("reference");
      w.direction = {0, 1, 0};
      sc.sensors.push_back(w);
    }
  }
  const Truth truth = simulate_truth(sc);
  for (std::size_t k = 0; k < gauges; ++k) {
    const std::string& n = sc.sensors[k].name;
    const auto &g = column(truth.table, n), &a = column(truth.table, n + "_at"), &r = column(truth.table, n + "_ref");
    double worst = 0.0, peak = 0.0;
    for (std::size_t i = 0; i < g.size(); ++i) {
      worst = std::max(worst, std::abs(g[i] - (a[i] - r[i])));
      peak = std::max(peak, std::abs(g[i]));
    }
    std::printf("  %-8s peak %.3e, largest |gauge - (w(s) - w(r))| %.3e\n", n.c_str(), peak, worst);
    EXPECT_GT(peak, 0.0) << n;
    EXPECT_LE(worst, 1e-12 * peak) << n;
  }
}

TEST(RelativeDisplacementGauge, TheChainsGaugesConvergeOntoTheFiniteElementOnesAtSecondOrder) {
  // Station displacements approach the continuum's at O(h²), and so do their differences
  // (measured: 2.9e-2, 7.4e-3, 1.9e-3 and 2.1e-2, 5.4e-3, 1.4e-3: rates 1.94 and 1.95).
  expect_second_order_convergence(gauge_strip(), "scoleid-gauge-trajectories");
}

TEST(RelativeDisplacementGauge, EIRhoAAndZetaFromTwoGaugesOnTheEightySegmentTruth) {
  expect_identified_from_the_truth(gauge_strip());
}
