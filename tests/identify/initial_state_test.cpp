// A record that starts with the structure already moving (docs/theory.md §6.9): the initial state
// in the model's lowest modes, profiled out at every q. The gradient of the profiled cost against
// central differences (displacement sensors, whose costate gradient carries the boundary term
// p(t0)ᵀ M_j u̇(t0), and rate sensors), the Taylor remainder, the stored and checkpointed passes
// alike, and what the profiled-out state buys: the cost at the truth falls to the part the basis
// does not hold.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "common/test_data.h"
#include "scoleid/io/scenario.h"
#include "test_support.h"

using namespace scoleid::identify;
using test_support::Case;
using test_support::make_case;
using test_support::max_rel;

namespace {
const std::string kRinging = scoleid::test::test_scenario("initial_state_test/grad-ringing");
const std::string kRingingRates = scoleid::test::test_scenario("initial_state_test/grad-ringing-rates");

VectorXd truth_of(const Case& c) {
  VectorXd q(c.p->params->size());
  for (int i = 0; i < q.size(); ++i) q[i] = c.p->true_values.at(c.p->params->names()[static_cast<std::size_t>(i)]);
  return q;
}

TEST(InitialState, TheRecordStartsWhereTheScenarioSays) {
  Case c = make_case(kRinging, false);
  EXPECT_NEAR(c.p->data.t.front(), 0.6, 1e-12);
  EXPECT_NEAR(c.p->data.t.back(), 2.2, 1e-12);
  ASSERT_TRUE(c.obj->estimates_initial_state());
  // The tip's record is already moving at its first sample: the earlier tap rings.
  EXPECT_GT(std::abs(c.p->data.z(0, 0)), 1e-3 * c.p->data.z.col(0).cwiseAbs().maxCoeff());
}

// The Gauss–Newton gradient (the initial state's and the parameters' tangents stepped with the
// state, then the Schur complement) is the exact derivative of the discrete profiled cost; the
// costate gradient is the continuous one's, and meets it at the integrator's order as the step falls.
void check_gradients(const std::string& yaml, double order, double finest) {
  std::vector<double> gap;
  for (double h : {0.005, 0.0025, 0.00125, 0.000625}) {
    Case c = make_case(yaml, false, h);
    const VectorXd q = c.p->params->initial();
    VectorXd g_adj, g_gn;
    MatrixXd H;
    c.obj->cost_and_gradient(q, g_adj);
    c.obj->gauss_newton(q, g_gn, H);
    gap.push_back(max_rel(g_adj, g_gn));
    if (h == 0.005) {
      const VectorXd g_fd = test_support::richardson_gradient(*c.obj, q, 1e-3);
      std::printf("  h %g: Gauss-Newton vs central differences %.2e\n", h, max_rel(g_gn, g_fd));
      EXPECT_LT(max_rel(g_gn, g_fd), 1e-6);
      test_support::expect_second_order(test_support::taylor_remainders(*c.obj, q, 7), 1, 5);
    }
    std::printf("  h %-9g costate vs Gauss-Newton %.3e%s\n", h, gap.back(),
                gap.size() > 1 ? (" (ratio " + std::to_string(gap[gap.size() - 2] / gap.back()) + ")").c_str() : "");
  }
  for (std::size_t k = 1; k < gap.size(); ++k) EXPECT_GT(gap[k - 1] / gap[k], order) << "halving " << k;
  EXPECT_LT(gap.back(), finest);
}
}  // namespace

// Displacement sensors: the costate's gradient carries −p(t0)ᵀ M_j u̇(t0) (the mass term by parts);
// third order in the step.
TEST(InitialState, GradientWithDisplacementSensors) { check_gradients(kRinging, 6.0, 1e-6); }
// Rate sensors: no boundary term; the accelerometer's costate approaches third order.
TEST(InitialState, GradientWithRateSensors) { check_gradients(kRingingRates, 3.5, 5e-5); }

TEST(InitialState, CheckpointedGradientIsTheStoredOne) {
  Case stored = make_case(kRinging, false);
  ObjectiveOptions o = stored.p->objective_options;
  o.checkpoint_points = 7;
  Objective ck(stored.p->model(), *stored.p->params, stored.p->signals, stored.p->data, o);
  const VectorXd q = stored.p->params->initial();
  VectorXd g1, g2;
  const double J1 = stored.obj->cost_and_gradient(q, g1);
  const double J2 = ck.cost_and_gradient(q, g2);
  std::printf("  stored J %.12e, checkpointed J %.12e, gradient difference %.2e\n", J1, J2, max_rel(g2, g1));
  EXPECT_NEAR(J2, J1, 1e-12 * J1);
  EXPECT_LT(max_rel(g2, g1), 1e-9);
}

TEST(InitialState, TheProfiledStateExplainsTheRinging) {
  // At the true parameters the model from rest misses the earlier tap's ringing; with the initial
  // state profiled out only what the basis (the identifier's low modes) does not hold remains.
  Case est = make_case(kRinging, false);
  std::string rest_yaml = kRinging;
  rest_yaml.replace(rest_yaml.find("initial_state: estimate"), 23, "initial_state: rest");
  Case rest = make_case(rest_yaml, false);
  ASSERT_FALSE(rest.obj->estimates_initial_state());
  const VectorXd q = truth_of(est);
  const double J_est = est.obj->cost(q), J_rest = rest.obj->cost(q);
  const VectorXd ab = est.obj->initial_state_coefficients(q);
  std::printf("  J at the truth: from rest %.3e, initial state estimated %.3e (%ld coefficients)\n", J_rest, J_est,
              static_cast<long>(ab.size()));
  EXPECT_EQ(ab.size(), 2 * est.obj->initial_state_basis().cols());
  EXPECT_LT(J_est, 1e-3 * J_rest);
}
