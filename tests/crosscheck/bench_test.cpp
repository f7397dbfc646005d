// A lab bench on the Simbody truth (docs/theory.md §2.5, the built-in bench-cantilever): a steel
// strip on a compliant clamp, a shaker's fixture at 0.40 m on the beam side of the measured force,
// two accelerometers whose masses load the strip. The chain's natural frequencies meet the exact
// transfer-matrix ones after extrapolation in the number of segments, and the FE model's at rate
// 4; from one record sampled at 1 kHz, EI, ρA, ζ, the clamp's k_θ and the fixture's mass are found
// within 2 % from starts 30 % off on either side, each called identifiable with an interval that
// covers the truth, and the identified model's first three frequencies within their intervals of
// the exact ones.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "scoleid/crosscheck/modes.h"
#include "scoleid/identify.h"
#include "scoleid/identify/fe/analytic_beam.h"
#include "scoleid/truth.h"

using namespace scoleid;

TEST(Bench, ChainAndFiniteElementsMeetTheExactFrequencies) {
  const io::Scenario sc = io::load_scenario("bench-cantilever");
  crosscheck::ModesOptions mo;
  mo.count = 5;
  // 80, 160 and 320 segments (at 640 the chain's linearisation by differences loses the first
  // mode's sixth digit).
  mo.segments = 80;
  const crosscheck::ModesReport r = crosscheck::compare_modes(sc, mo);
  ASSERT_EQ(r.modes.size(), 5u);
  EXPECT_FALSE(r.analytic.empty());
  for (const auto& m : r.modes) {
    SCOPED_TRACE("mode " + std::to_string(m.index));
    // The chain's extrapolation leaves O(n⁻⁴) (measured <= 6e-6).
    EXPECT_LT(std::abs(m.chain_extrapolated / m.analytic_hz - 1.0), 3e-5);
    // The finest FE (4 × 16 elements; measured 1.3e-7 for mode 1, 2.5e-6 for mode 5).
    EXPECT_LT(std::abs(m.fe_hz.back() / m.analytic_hz - 1.0), 5e-6);
    EXPECT_GE(m.mac, 0.99);
  }
}

TEST(Bench, OneShakerRecordGivesTheStripTheClampAndTheFixture) {
  const io::Scenario sc = io::load_scenario("bench-cantilever");
  const Truth truth = simulate_truth(sc);
  const auto exact = identify::analytic::point_element_omegas(sc.beam, 3);
  const std::string opposite =
      "{EI: 7.875, rho_A: 0.765, zeta: 0.0035, supports.left.k_theta: 1060, attachments.shaker.mass: 0.042}";
  for (const std::string& start : {std::string(), opposite}) {
    io::Scenario s = sc;
    if (!start.empty()) {
      std::string yaml = io::builtin_scenario_yaml("bench-cantilever");
      const auto at = yaml.find("initial: {");
      yaml.replace(at, yaml.find('}', at) + 1 - at, "initial: " + start);
      s = io::parse_scenario(yaml, "bench, opposite start");
    }
    const auto wall0 = std::chrono::steady_clock::now();
    const Identification id = identify_parameters(s, DataSource::in_memory(truth.table, "bench truth", truth.meta), {});
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    std::printf("start %s: %.1f s\n%s", start.empty() ? "the scenario's" : start.c_str(), wall, id.FullReport().c_str());
    ASSERT_TRUE(id.converged()) << id.verdict();
    const auto& r = id.result();
    ASSERT_EQ(r.names.size(), 5u);
    for (std::size_t i = 0; i < r.names.size(); ++i) {
      const auto e = static_cast<Eigen::Index>(i);
      const double t = r.truth.at(r.names[i]);
      EXPECT_LT(std::abs(r.estimate[e] / t - 1.0), 0.02) << r.names[i];
      ASSERT_TRUE(r.ident.identifiable[i]) << r.names[i] << ": " << r.ident.reason[i];
      EXPECT_LE(std::abs(r.estimate[e] - t), r.interval.half_width[e]) << r.names[i];
    }
    ASSERT_GE(r.modes.size(), 3u);
    for (std::size_t k = 0; k < 3; ++k) {
      const double f = exact[k] / (2.0 * M_PI);
      std::printf("  mode %zu: identified %.5f Hz ± %.3g, exact %.5f Hz\n", k + 1, r.modes[k].frequency_hz,
                  r.modes[k].frequency_half_width_hz, f);
      EXPECT_LE(std::abs(r.modes[k].frequency_hz - f), r.modes[k].frequency_half_width_hz) << "mode " << k + 1;
    }
  }
}
