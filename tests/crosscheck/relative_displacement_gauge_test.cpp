// Relative-displacement gauges across the gap: the Simbody chain's reading is the difference of
// its own displacement read-outs at the two stations, and EI, ρA and ζ are identified from the
// chain's gauges through the front doors.
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

// The clamped strip of the identifier's gauge test, at the truth's 80 segments.
io::Scenario strip() {
  return io::parse_scenario(scoleid::test::test_scenario("relative_displacement_test/gauge-strip"), "gauge strip");
}

const std::vector<double>& column(const io::DataTable& t, const std::string& name) {
  const int c = t.find(name);
  EXPECT_GE(c, 0) << name;
  return t.columns.at(static_cast<std::size_t>(std::max(c, 0)));
}

}  // namespace

TEST(RelativeDisplacementGauge, TheChainReadsTheDifferenceOfItsTwoStationsDisplacements) {
  // The same truth with displacement sensors at each gauge's two stations: a gauge must read
  // w(s) − w(r) of the chain to rounding (both read-outs are the same station positions).
  io::Scenario sc = strip();
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
  // The chain's station displacements approach the continuum's at O(h²), and so do their
  // differences: the relative RMS difference to a fine FE model falls by about 4 per doubling of
  // the segments, and at 80 segments it is below 1 %.
  crosscheck::TrajectoryOptions o;
  o.segments = 20;
  o.levels = 3;
  o.elements = 96;
  const auto dir = std::filesystem::temp_directory_path() / "scoleid-gauge-trajectories";
  std::filesystem::remove_all(dir);
  const auto r = crosscheck::compare_trajectories(strip(), o, dir.string());
  for (const auto& s : r.sensors) {
    std::printf("  %-8s relative RMS", s.name.c_str());
    for (double e : s.relative_rms) std::printf(" %.3e", e);
    std::printf("  rate %.2f\n", s.rate);
    EXPECT_GT(s.rate, 1.7) << s.name;
    EXPECT_LT(s.rate, 2.5) << s.name;
    EXPECT_LT(s.relative_rms.back(), 1e-2) << s.name;
  }
  std::filesystem::remove_all(dir);
}

TEST(RelativeDisplacementGauge, EIRhoAAndZetaFromTwoGaugesOnTheEightySegmentTruth) {
  const io::Scenario sc = strip();
  const Truth truth = simulate_truth(sc);
  const Identification id = identify_parameters(sc, DataSource::in_memory(truth.table, "gauge truth", truth.meta), {});
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
