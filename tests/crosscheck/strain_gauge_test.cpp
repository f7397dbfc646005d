// Strain gauges across the gap: the Simbody chain's joint moments against the finite-element
// curvature row, and EI, ρA and ζ identified from the chain's gauges through the front doors.
#include <gtest/gtest.h>

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

}  // namespace

TEST(StrainGauge, TheChainsGaugesConvergeOntoTheFiniteElementCurvatureAtSecondOrder) {
  // The chain's joint moments are EI w_ss at the joints to O(h²), and the gauges read them linearly
  // between joints: the relative RMS difference to the fine FE model falls by about 4 per doubling
  // (measured: 4.8e-2, 1.2e-2, 3.2e-3 at the root gauge, 8.9e-2, 2.3e-2, 6.0e-3 at midspan, for 20,
  // 40 and 80 segments: rates 1.92 and 1.93), and at 80 segments it is below 1 %.
  crosscheck::TrajectoryOptions o;
  o.segments = 20;
  o.levels = 3;
  o.elements = 96;
  const auto dir = std::filesystem::temp_directory_path() / "scoleid-strain-trajectories";
  std::filesystem::remove_all(dir);
  const auto r = crosscheck::compare_trajectories(strip(), o, dir.string());
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

TEST(StrainGauge, EIRhoAAndZetaFromTwoGaugesOnTheEightySegmentTruth) {
  const io::Scenario sc = strip();
  const Truth truth = simulate_truth(sc);
  const Identification id = identify_parameters(sc, DataSource::in_memory(truth.table, "strain truth", truth.meta), {});
  std::printf("%s", id.FullReport().c_str());
  EXPECT_TRUE(id.converged()) << id.verdict();
  const auto& r = id.result();
  for (std::size_t i = 0; i < id.names().size(); ++i) {
    const std::string& n = id.names()[i];
    const double e = id.estimate()[static_cast<Eigen::Index>(i)] / r.truth.at(n) - 1.0;
    EXPECT_LT(std::abs(e), n == "zeta" ? 0.05 : 1e-2) << n;
  }
}
