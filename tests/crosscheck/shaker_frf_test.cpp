// A shaker test in the frequency domain (the built-in shaker-frf, docs/theory.md §6.10): the
// Simbody chain driven by a periodic multisine, recorded in steady state; the FRFs at its lines
// give EI, rho_A and zeta within 1 % from starts 20 % off, each identifiable with an interval that
// covers the truth, the fit explained, in seconds. (The truth at test::kIdentificationTruthAccuracy:
// at the scenario's own 1e-9 its 32 s take a quarter of an hour and move the estimates by < 1e-4.)
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>

#include "scoleid/identify.h"
#include "scoleid/truth.h"
#include "common/truth_support.h"

using namespace scoleid;

TEST(ShakerFrf, TheFrfsOfASteadyMultisineRecordGiveTheStrip) {
  const io::Scenario sc = io::load_scenario("shaker-frf");
  ASSERT_EQ(sc.identification.domain, io::Domain::Frequency);
  const Truth truth = test::identification_truth(sc);
  ASSERT_FALSE(truth.table.t.empty());
  const auto t0 = std::chrono::steady_clock::now();
  const Identification id = identify_parameters(sc, DataSource::in_memory(truth.table, "shaker truth", truth.meta), {});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%s\nidentified in %.3g s\n", id.FullReport().c_str(), seconds);
  ASSERT_TRUE(id.converged()) << id.verdict();
  const auto& r = id.result();
  ASSERT_TRUE(id.problem().frf.has_value());
  EXPECT_EQ(id.problem().frf->estimator, "lines");
  EXPECT_EQ(id.problem().frf->lines(), 359);
  ASSERT_EQ(r.names.size(), 3u);
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const double t = r.truth.at(r.names[i]);
    std::printf("%-6s %+.3e of the truth, interval ±%.3e\n", r.names[i].c_str(), r.estimate[e] / t - 1.0, r.interval.half_width[e] / t);
    EXPECT_LT(std::abs(r.estimate[e] / t - 1.0), 0.01) << r.names[i];
    ASSERT_TRUE(r.ident.identifiable[i]) << r.names[i] << ": " << r.ident.reason[i];
    EXPECT_LE(std::abs(r.estimate[e] - t), r.interval.half_width[e]) << r.names[i];
  }
  EXPECT_LT(seconds, 10.0) << "the FRF path end to end";
}
