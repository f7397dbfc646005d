// Square-root (Chen–Russell) damping in the Hencky chain (model/beam_chain.h, docs/theory.md
// §9.2): each bar carries the torque −D_i ω_i, D_i = ∫_bar d ds. The chain's linearised modes
// (linearisation.h) are compared with the exact damped modes of the FE model
// (identify/fe/modal.h).
//
// Pinned–pinned, uniform: mode k of the n-bar chain is the discrete sine w_j = sin(j α), α = kπ/n,
// whose slope energy, strain energy and kinetic energy are the continuum's times S, S² and
// (2 + cos α)/3, S = (sin(α/2)/(α/2))². Its damping ratio D/(2√(KM)) is therefore exactly
//     ζ_chain = ζ √(3 / (2 + cos α)) = ζ (1 + α²/12 + O(α⁴)),
// an O(1/n²) lumping error, while the FE model gives ζ to its own (much smaller) error.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "scoleid/identify/fe/beam_model.h"
#include "scoleid/identify/fe/modal.h"
#include "scoleid/model/beam_chain.h"
#include "scoleid/model/linearisation.h"

using namespace scoleid;

namespace {

constexpr double kPi = 3.14159265358979323846;

io::BeamSpec beam(io::EndCondition left, io::EndCondition right, double zeta) {
  io::BeamSpec b;
  b.length = 10.0;
  b.left = left;
  b.right = right;
  b.rho_A = 67.0;
  b.EI = {23000.0};
  b.zeta = zeta;
  return b;
}

std::vector<model::Mode> chain_modes(const io::BeamSpec& b, int n) {
  model::BeamChain chain(b, n);
  chain.system().realizeTopology();
  return model::natural_modes(chain.system(), chain.system().getDefaultState());
}

std::vector<identify::DampedMode> fe_modes(const io::BeamSpec& b, int elements) {
  const identify::BeamFE fe = identify::build_beam(b, elements, 1, {}, {});
  const identify::AssembledModel a =
      identify::assemble(fe.model, identify::beam_coefficients(fe, b.rho_A, b.EI, b.zeta, b.c_kv));
  return identify::damped_modes(Eigen::MatrixXd(a.M), Eigen::MatrixXd(a.D), Eigen::MatrixXd(a.K));
}

}  // namespace

TEST(BeamDampingChain, PinnedModesDecayAsTheFEToTheLumpingError) {
  const double zeta = 0.02;
  const io::BeamSpec b = beam(io::EndCondition::Pinned, io::EndCondition::Pinned, zeta);
  const auto fe = fe_modes(b, 60);
  ASSERT_GE(fe.size(), 3u);
  std::printf("  %4s %4s %12s %12s %12s %12s %12s\n", "n", "mode", "zeta chain", "zeta FE", "chain/FE-1",
              "predicted", "alpha^2/12");
  std::vector<double> first;  // chain/FE − 1 for mode 1 at each n
  for (int n : {10, 20, 40}) {
    const auto ch = chain_modes(b, n);
    ASSERT_GE(ch.size(), 3u) << n;
    for (int k = 1; k <= 3; ++k) {
      const double alpha = k * kPi / n;
      const double z_chain = ch[static_cast<std::size_t>(k - 1)].damping_ratio;
      const double z_fe = fe[static_cast<std::size_t>(k - 1)].zeta;
      const double predicted = std::sqrt(3.0 / (2.0 + std::cos(alpha))) - 1.0;
      const double diff = z_chain / z_fe - 1.0;
      std::printf("  %4d %4d %12.9f %12.9f %12.3e %12.3e %12.3e\n", n, k, z_chain, z_fe, diff, predicted,
                  alpha * alpha / 12.0);
      // The chain's ratio is the discrete formula to the linearisation's differencing error; the
      // FE's is ζ to < 1e-6 here; so chain/FE − 1 is the lumping error α²/12 (1 + O(α²)).
      EXPECT_NEAR(z_chain / zeta - 1.0, predicted, 1e-6) << "n " << n << " mode " << k;
      EXPECT_GT(diff, 0.0) << "n " << n << " mode " << k;
      EXPECT_LT(diff, 1.05 * alpha * alpha / 12.0 + 2e-6) << "n " << n << " mode " << k;
      if (k == 1) first.push_back(diff);
    }
  }
  for (std::size_t i = 1; i < first.size(); ++i) EXPECT_NEAR(first[i - 1] / first[i], 4.0, 0.2) << "halving " << i;
}

TEST(BeamDampingChain, CantileverFirstModeConvergesToTheFE) {
  // No closed form for the chain here; its first-mode ratio approaches the FE's (1.32ζ, docs/theory.md
  // §2.2) at O(1/n²): measured −4.8e-3, −1.2e-3, −3.0e-4 at n = 10, 20, 40.
  const double zeta = 0.05;
  const io::BeamSpec b = beam(io::EndCondition::Clamped, io::EndCondition::Free, zeta);
  const auto fe = fe_modes(b, 60);
  ASSERT_FALSE(fe.empty());
  std::printf("  FE (60 elements) first-mode ratio %.9f (zeta %.3f)\n", fe[0].zeta, zeta);
  std::vector<double> diff;
  for (int n : {10, 20, 40}) {
    const auto ch = chain_modes(b, n);
    ASSERT_FALSE(ch.empty());
    diff.push_back(ch[0].damping_ratio / fe[0].zeta - 1.0);
    std::printf("  n %3d: chain ratio %.9f, chain/FE - 1 = %+.3e\n", n, ch[0].damping_ratio, diff.back());
  }
  for (std::size_t i = 1; i < diff.size(); ++i) EXPECT_GT(std::abs(diff[i - 1] / diff[i]), 3.0) << "halving " << i;
  EXPECT_LT(std::abs(diff.back()), 2e-3);
}
