// A tap test recorded from 0.7 s after a first hit (the built-in tap-late-start, docs/theory.md
// §6.9): the Simbody chain, already ringing at the record's first sample, through a 400 Hz
// acquisition filter. With the initial state estimated, EI, ρA and ζ within 1 % from starts 20 %
// off, each identifiable with an interval that covers the truth; from rest the same record is
// refused (not converged) and the run names the sensor that moves before any input acts.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "scoleid/identify.h"
#include "scoleid/truth.h"

using namespace scoleid;

TEST(LateStart, TheInitialStateEstimatedGivesTheStripFromARingingRecord) {
  const io::Scenario sc = io::load_scenario("tap-late-start");
  ASSERT_EQ(sc.identification.initial_state, io::InitialState::Estimate);
  const Truth truth = simulate_truth(sc);
  ASSERT_FALSE(truth.table.t.empty());
  EXPECT_NEAR(truth.table.t.front(), sc.simulation.record_start, 1e-9);

  const Identification id = identify_parameters(sc, DataSource::in_memory(truth.table, "late-start truth", truth.meta), {});
  std::printf("%s", id.FullReport().c_str());
  ASSERT_TRUE(id.converged()) << id.verdict();
  const auto& r = id.result();
  ASSERT_EQ(r.names.size(), 3u);
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const double t = r.truth.at(r.names[i]);
    EXPECT_LT(std::abs(r.estimate[e] / t - 1.0), 0.01) << r.names[i];
    ASSERT_TRUE(r.ident.identifiable[i]) << r.names[i] << ": " << r.ident.reason[i];
    EXPECT_LE(std::abs(r.estimate[e] - t), r.interval.half_width[e]) << r.names[i];
  }
  // The state it starts in: the basis and its coefficients, the strip's first mode the largest.
  ASSERT_FALSE(r.initial_state_hz.empty());
  const auto m = static_cast<Eigen::Index>(r.initial_state_hz.size());
  ASSERT_EQ(r.initial_state_coefficients.size(), 2 * m);
  Eigen::Index biggest = 0;
  r.initial_state_coefficients.head(m).cwiseAbs().maxCoeff(&biggest);
  EXPECT_EQ(biggest, 0);

  // From rest: the ringing is a response the model cannot make.
  io::Scenario rest = sc;
  rest.identification.initial_state = io::InitialState::Rest;
  const Identification at_rest =
      identify_parameters(rest, DataSource::in_memory(truth.table, "late-start truth", truth.meta), {});
  std::printf("from rest: %s\n", at_rest.verdict().c_str());
  EXPECT_FALSE(at_rest.converged());
  bool named = false;
  for (const auto& w : at_rest.problem().warnings) named = named || w.find("moving at the record's start") != std::string::npos;
  EXPECT_TRUE(named);
}
