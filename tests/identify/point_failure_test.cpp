// What a failed evaluation at a trial point means (identify/point_failure.h; docs/theory.md
// §10.1a): a model that cannot be evaluated there (std::domain_error, a solver's
// std::runtime_error) is a rejected point and the optimiser goes on; a defect (any other
// std::logic_error) or an input the door should have refused (io::InputError) reaches the caller
// unchanged, never a verdict about the data. Checked on a quadratic misfit whose evaluations throw
// beyond a wall the first Gauss–Newton step crosses, and through the time integrator.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "scoleid/identify/door/scenario_door.h"
#include "scoleid/identify/fe/structure.h"
#include "scoleid/identify/inverse/misfit.h"
#include "scoleid/identify/inverse/optimizers.h"
#include "scoleid/identify/point_failure.h"
#include "scoleid/identify/time/second_order_solver.h"
#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/scenario.h"

using namespace scoleid::identify;

namespace {

// J(q) = Σ (q_i − 2)², its minimum at q = 2; from q0 = 1 the Gauss–Newton step lands there at
// once, but every evaluation with q_0 > wall throws E: the step is rejected (a point failure) and
// the trust region shrinks until the steps stay below the wall, or the exception escapes.
template <class E>
class Walled final : public Misfit {
public:
  explicit Walled(double wall) : wall_(wall) {}
  int size() const override { return 2; }
  double horizon() const override { return 1.0; }
  double data_start() const override { return 0.0; }
  double data_end() const override { return 1.0; }
  void set_horizon(double) override {}
  bool has_horizon() const override { return false; }
  long data_points() const override { return 100; }
  double cost(const VectorXd& q) override {
    check(q);
    return (q.array() - 2.0).square().sum();
  }
  double cost_and_gradient(const VectorXd& q, VectorXd& g) override {
    g = 2.0 * (q.array() - 2.0).matrix();
    return cost(q);
  }
  double gauss_newton(const VectorXd& q, VectorXd& g, MatrixXd& H, MisfitProfile* profile) override {
    H = 2.0 * MatrixXd::Identity(2, 2);
    if (profile) *profile = misfit_profile(q);
    return cost_and_gradient(q, g);
  }
  MisfitProfile misfit_profile(const VectorXd& q) override { return {{1.0}, {cost(q)}}; }
  VectorXd gauss_newton_product(const VectorXd&, const VectorXd& v) override { return 2.0 * v; }
  bool has_matrix_free_products() const override { return true; }
  int evaluations_beyond = 0;

private:
  void check(const VectorXd& q) {
    if (q[0] > wall_) {
      ++evaluations_beyond;
      throw E("beyond the wall");
    }
  }
  double wall_;
};

OptimizerOptions options() {
  OptimizerOptions o;
  o.method = scoleid::io::Method::GaussNewton;
  o.continuation = false;
  o.max_iterations = 40;
  return o;
}

}  // namespace

TEST(PointFailure, ClassifiesTheStandardKinds) {
  EXPECT_TRUE(point_failure(std::domain_error("mass not positive definite")));
  EXPECT_TRUE(point_failure(std::runtime_error("CVODES failed")));
  EXPECT_FALSE(point_failure(std::logic_error("defect")));
  EXPECT_FALSE(point_failure(std::invalid_argument("defect")));
  EXPECT_FALSE(point_failure(std::out_of_range("defect")));
  EXPECT_FALSE(point_failure(scoleid::io::InputError("x.yaml: field must be ...")));
  EXPECT_FALSE(point_failure(std::bad_alloc()));
}

// A model that does not exist beyond the wall: the optimiser rejects those trials and stops at the
// wall, where its steps (along q − 2, both coordinates alike) would cross it: J decreased from
// its start (2) to about 2 (2 − 1.5)² = 0.5, no exception.
TEST(PointFailure, AModelThatCannotBeEvaluatedIsARejectedStep) {
  for (const bool domain : {true, false}) {
    SCOPED_TRACE(domain ? "domain_error" : "runtime_error");
    OptimizerSummary s;
    int beyond = 0;
    if (domain) {
      Walled<std::domain_error> m(1.5);
      s = minimize(m, VectorXd::Ones(2), options());
      beyond = m.evaluations_beyond;
    } else {
      Walled<std::runtime_error> m(1.5);
      s = minimize(m, VectorXd::Ones(2), options());
      beyond = m.evaluations_beyond;
    }
    EXPECT_GT(beyond, 0) << "the first step should have crossed the wall";
    ASSERT_EQ(s.q.size(), 2);
    EXPECT_LE(s.q[0], 1.5);
    EXPECT_GT(s.q[0], 1.4);
    EXPECT_TRUE(std::isfinite(s.cost));
    EXPECT_LT(s.cost, 0.75);
    EXPECT_GE(s.cost, 0.5);
  }
}

// A defect met at a trial point reaches the caller as it is, whatever kind of std::logic_error.
TEST(PointFailure, ADefectAtATrialPointReachesTheCaller) {
  {
    Walled<std::out_of_range> m(1.5);
    EXPECT_THROW(minimize(m, VectorXd::Ones(2), options()), std::out_of_range);
  }
  {
    Walled<std::logic_error> m(1.5);
    EXPECT_THROW(minimize(m, VectorXd::Ones(2), options()), std::logic_error);
  }
  {
    Walled<scoleid::io::InputError> m(1.5);
    EXPECT_THROW(minimize(m, VectorXd::Ones(2), options()), scoleid::io::InputError);
  }
}

// Through the integrator (CVODES BDF, whose C callbacks hold an exception until CVODES returns): a
// load that throws a defect comes out as that defect; one the model cannot give at that time comes
// out as a point failure naming it (as it is, or as the integrator's failure).
TEST(PointFailure, TheIntegratorsCallbacksKeepTheKind) {
  SparseMatrix M(1, 1), D(1, 1), K(1, 1);
  M.insert(0, 0) = 1.0;
  D.insert(0, 0) = 0.1;
  K.insert(0, 0) = 4.0;
  SolverOptions so;
  so.integrator = SolverOptions::Integrator::Bdf;
  SecondOrderSolver solver(M, D, K, {0}, so);
  const auto throwing = [](auto error) {
    return [error](double t, double* F) {
      if (t > 0.5) throw error;
      F[0] = 1.0;
    };
  };
  EXPECT_THROW(solver.solve(0.0, 1.0, throwing(std::out_of_range("defect")), {}), std::out_of_range);
  try {
    solver.solve(0.0, 1.0, throwing(std::domain_error("no load there")), {});
    ADD_FAILURE() << "no failure";
  } catch (const std::exception& e) {  // as it is, or as the integrator's failure naming it
    EXPECT_TRUE(point_failure(e)) << e.what();
    EXPECT_NE(std::string(e.what()).find("no load there"), std::string::npos) << e.what();
  }
  // And the solver works again afterwards.
  const Trajectory tr = solver.solve(0.0, 1.0, [](double, double* F) { F[0] = 1.0; }, {});
  EXPECT_GT(tr.times().size(), 2u);
}

// Below the door a scenario is taken as valid: a model built on one that went around it (a sensor
// off the beam, a sensor on the mast of a frame) is a defect, a std::logic_error that is no point
// failure; the door (check_scenario) refuses the same scenario as an input error naming the field.
TEST(PointFailure, AModelBuiltAroundTheDoorIsADefectTheDoorRefusesAsInput) {
  scoleid::io::Scenario sc = scoleid::io::load_scenario("paper-beam-1");
  sc.sensors[0].location = 2 * sc.beam.length;
  try {
    make_structure(sc, 4);
    ADD_FAILURE() << "a sensor off the beam was modelled";
  } catch (const std::logic_error& e) {
    EXPECT_FALSE(point_failure(e)) << e.what();
  }
  try {
    check_scenario(sc);
    ADD_FAILURE() << "the door let a sensor off the beam through";
  } catch (const scoleid::io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sensors[0].location must lie on the beam"), std::string::npos) << e.what();
  }
  scoleid::io::Scenario f = scoleid::io::load_scenario("frame-4storey");
  f.inputs[0].at = scoleid::io::Site::Mast;
  EXPECT_THROW(make_structure(f, 2), std::logic_error);
  EXPECT_THROW(check_scenario(f), scoleid::io::InputError);
}
