// scole-crosscheck identify (crosscheck/identify_study.h) on paper-scole-1: the identifier's error
// on the Simbody truth converges at the chain's second order in n to the truth when both sides
// carry the section's bending rotary inertia, and to a measured offset when the identifier's mast
// is Euler–Bernoulli (docs/theory.md §11.3). Slow: six Simbody truths up to 160 segments.
#include "scoleid/crosscheck/identify_study.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "scoleid/io/scenario.h"

using namespace scoleid;
namespace fs = std::filesystem;

namespace {
crosscheck::IdentifyStudy study(const io::Scenario& sc, const std::string& tag) {
  const fs::path dir = fs::temp_directory_path() / ("scoleid-xc-id-" + tag + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const auto s = crosscheck::identify_study(sc, crosscheck::IdentifyStudyOptions{}, dir.string());
  fs::remove_all(dir);
  return s;
}
}  // namespace

TEST(IdentifyStudy, ScoleBiasIsTheChainsLumpingAndExtrapolatesAway) {
  // Both sides carry the section's bending rotary inertia (docs/theory.md §3.3, §9.3): what the
  // chain adds is its lumping, second order in n, and the extrapolated estimates meet the truth to
  // the truth's geometric nonlinearity (measured with the Gauss–Legendre truth: q1 3e-5, q2 1.2e-4,
  // ten times smaller with the loads scaled by 0.1, while FE-on-FE is 2e-6; a trapezoidal truth's
  // time error shifts both by about -3e-5).
  io::Scenario sc = io::load_scenario("paper-scole-1");
  const auto nominal = study(sc, "nominal");
  ASSERT_TRUE(nominal.all_converged());
  for (const auto& p : nominal.parameters) {
    SCOPED_TRACE(p.name);
    std::printf("  %s: extrapolated error %.3e, rate %.2f, FE-on-FE %.3e\n", p.name.c_str(), p.extrapolated_error(), p.rate,
                p.fe_on_fe_error());
    EXPECT_NEAR(p.rate, 2.0, 0.3);
    EXPECT_LT(std::abs(p.extrapolated_error()), 2e-4);
    EXPECT_LT(std::abs(p.fe_on_fe_error()), 1e-4);
  }
  // The identifier's mast without it (Euler–Bernoulli) against the same truth: the extrapolated
  // error is the missing physics, well above the lumping's.
  sc.scole.bending_rotary_inertia = false;
  sc.truth.overrides = "scole: {bending_rotary_inertia: true}";
  const auto eb = study(sc, "euler-bernoulli");
  ASSERT_TRUE(eb.all_converged());
  for (const auto& p : eb.parameters) {
    SCOPED_TRACE(p.name);
    EXPECT_LT(p.extrapolated_error(), -5e-4);
    EXPECT_GT(p.extrapolated_error(), -3e-3);
  }
}
