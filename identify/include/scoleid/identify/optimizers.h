#pragma once
// Minimisers of J(q) over positive parameters. All work on x = log q (positivity by
// construction, and steps measured relative to each parameter); gradients transform as
// ∂J/∂x_i = q_i ∂J/∂q_i.
//
//   steepest-descent  the paper's update q_i ← q_i − w_i ∂J/∂q_i. With weights given, exactly
//                     that, halving the step while the cost does not decrease (monotone); without
//                     weights, w_i = α q_i² (steepest descent in log q) with α from backtracking.
//   lbfgs             limited-memory BFGS (m = 8) on x with an Armijo backtracking line search;
//                     one costate gradient per trial point.
//   gauss-newton      Levenberg–Marquardt on x from forward sensitivities:
//                     (H + λ diag H) δ = −g; λ = 0 first (pure Gauss–Newton), ×10 on rejection,
//                     and raised until ‖δ‖∞ <= 1 (a trust region of a factor e per step in q).
// Termination (stated in Summary::termination): relative parameter step below step_tolerance,
// scaled gradient ‖g_x‖∞ below gradient_tolerance·max(J, tiny), cost below cost_floor, relative
// cost decrease over an accepted step below cost_stall (only directions the data barely see are
// still moving: the identifiability report flags them), or the iteration limit.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "scoleid/identify/objective.h"

namespace scoleid::identify {

struct OptimizerOptions {
  std::string method = "gauss-newton";  // gauss-newton | lbfgs | steepest-descent
  int max_iterations = 50;
  double gradient_tolerance = 1e-9;
  double step_tolerance = 1e-5;
  double cost_floor = 1e-28;
  double cost_stall = 1e-5;   // relative decrease of J over an accepted step below which we stop
  std::vector<double> steepest_weights;  // w_i, paper form; empty = automatic
  bool IsValid(std::string* why) const;
};

struct IterationRecord {
  int k = 0;
  double cost = 0.0;
  VectorXd q;
  double gradient_norm = 0.0;  // ‖∂J/∂log q‖∞
};

struct OptimizerSummary {
  enum class Termination { StepTolerance, GradientTolerance, CostFloor, CostStalled, MaxIterations, LineSearchFailed };
  Termination termination = Termination::MaxIterations;
  std::string message;
  VectorXd q;
  double cost = 0.0;
  std::vector<IterationRecord> iterations;
  int iterations_done = 0;
  double wall_seconds = 0.0;
  bool converged() const {
    return termination == Termination::StepTolerance || termination == Termination::GradientTolerance ||
           termination == Termination::CostFloor || termination == Termination::CostStalled;
  }
  std::string BriefReport() const;
};

const char* to_string(OptimizerSummary::Termination t);

// `on_iteration` is called after every accepted iterate (and for k = 0), for progress output.
OptimizerSummary minimize(Objective& objective, const VectorXd& q0, const OptimizerOptions& options,
                          const std::function<void(const IterationRecord&)>& on_iteration = {});

}  // namespace scoleid::identify
