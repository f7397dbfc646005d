#pragma once
// The nonlinear SCOLE state equation (fe/scole_nonlinear.h) stepped forward and sampled at the
// data's times (docs/theory.md §5.6).
//
// y = [X, φ, e, V, Ω, ė], ẏ = f(t, y), by the identifier's ESDIRK table (esdirk_stepper.h:
// ESDIRK3(2)4L[2]SA from ARKODE; explicit first stage, equal diagonal γ, stiffly accurate) at a
// fixed step. Each implicit stage solves
//     G(Y_i) = Y_i − h γ f(t_n + c_i h, Y_i) − z_i = 0,   z_i = y_n + h Σ_{j<i} a_ij f(Y_j)
// by a modified Newton iteration from the predictor z_i + hγ F_{i−1} on the matrix I − h γ J,
// J = ∂f/∂y by difference quotients
// (dense, one f per column), factorised once and kept across stages and steps. It is refreshed
// (at the current iterate, and the stage restarted) only when the iteration stops contracting
// well — an iterate's correction larger than kRefreshContraction (0.3) of the previous one — or
// has not converged after kMaxNewton (6) iterations; the summary counts the refreshes. A step
// length that differs by more than 5 % from the factorised one refactorises with the same J.
// Convergence: every component's correction below newton_tol · max(|Y_j| + s_j, 1e-6), s_j the
// largest |y_j| met so far on the trajectory (the component's scale; the floor keeps components
// that stay zero to rounding from demanding corrections below rounding).
//
// Steps: the sample times and the inputs' breakpoints cut the record into intervals, each
// stepped in equal steps of at most max_step; a step evaluates the inputs strictly inside its own
// interval (at the neighbouring representable times of its ends: the right limit at its start,
// the left limit at its end), so a jump never lies inside a step. Outputs at a sample time t_k use
// f's accelerations with the inputs at t_k itself, as the truth and the linear model read them
// (after a jump that falls on a sample).
//
// The process never calls SUNDIALS' N_Vector: Simbody's libSimTKmath exports its own older
// copies of those symbols, and a program linking both (scole-crosscheck) would mix them.
#include <string>
#include <vector>

#include "scoleid/identify/fe/scole_nonlinear.h"
#include "scoleid/identify/time/esdirk_stepper.h"
#include "scoleid/io/signal.h"

namespace scoleid::identify {

struct NonlinearForwardOptions {
  double max_step = 0.0;     // 0 = a quarter of the sampling interval
  double newton_tol = 1e-10;
  bool IsValid(std::string* why = nullptr) const;
};

struct NonlinearForwardSummary {
  long steps = 0, rhs_evaluations = 0, jacobian_evaluations = 0, newton_iterations = 0;
  double seconds = 0.0;
};

// One step of the discrete trajectory, for the costate (inverse/nonlinear_objective.h): the
// stages' states Y_i and derivatives F_i = f(t_i, Y_i) (Y_0 = y_n, Y_{s−1} = y_{n+1}) and the
// input values they saw; `sample` ≥ 0 when the step ends on that sample.
struct NonlinearStep {
  double t = 0.0, h = 0.0;
  std::vector<VectorXd> Y, F, inputs;
  int sample = -1;
};

struct NonlinearResponse {
  std::vector<double> t;
  MatrixXd outputs;               // samples × sensors
  std::vector<VectorXd> states;   // y at each sample
  std::vector<VectorXd> sample_inputs;  // the input values at each sample (left limits)
  std::vector<NonlinearStep> steps;     // only when asked for (keep_steps)
  NonlinearForwardSummary summary;
};

// `times` increasing, starting at the initial time; y0 the initial state (empty: at rest).
// keep_steps: record every step's stages (memory steps × stages × 2 × state size doubles).
NonlinearResponse simulate_nonlinear(const ScoleNonlinear::Dynamics& dynamics, const std::vector<io::Signal>& signals,
                                     const std::vector<double>& times, const NonlinearForwardOptions& options = {},
                                     const VectorXd& y0 = VectorXd(), bool keep_steps = false);

// ∂f/∂y at (y, input values) by one-sided difference quotients, one f per column (the Newton
// matrices' Jacobian); `scale` the components' magnitudes for the increments.
MatrixXd nonlinear_jacobian(const ScoleNonlinear::Dynamics& dynamics, const VectorXd& y, const VectorXd& inputs,
                            const VectorXd& scale);
// The ESDIRK table both passes use.
const ButcherTable& nonlinear_table();

}  // namespace scoleid::identify
