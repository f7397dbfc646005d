#pragma once
// Output least squares for the nonlinear SCOLE model (fe/scole_nonlinear.h), its gradient by the
// discrete costate of the forward stepping (time/nonlinear_forward.h), docs/theory.md §6.7.
//
//   cost      J(q) = ½ Σ_k τ_k Σ_j R_j (z_j(y_k, u̇_k) − z̃_kj)²  over the samples t_k ≤ T,
//             τ_k the trapezoid weights of the sample times (so J ≈ ½ ∫ rᵀ R r dt), R_j =
//             1 / ((t_K − t0) · mean_k z̃_kj²), t_K the last sample on the horizon, as in
//             objective.h (the relative mean-square misfit).
//   forward   per step (ESDIRK, explicit first stage, stiffly accurate, diagonal γ):
//             Y_0 = y_n, Y_i = y_n + h Σ_{j≤i} a_ij F_j, F_j = f(t_j, Y_j; c), y_{n+1} = Y_{s−1}.
//   costate   the adjoint of exactly these equations (the linearisation along the computed
//             trajectory, time-varying): from ȳ_{n+1} (the later steps' and the sample's share),
//             for i = s−1 … 1 with S_i = Σ_{k>i} a_ki Λ_k,
//                 (I − hγ J_iᵀ) Λ_i = δ_{i,s−1} ȳ_{n+1} + h J_iᵀ S_i,   Φ_i = γ Λ_i + S_i,
//             then Φ_0 = Σ_{i≥1} a_i0 Λ_i and ȳ_n = Σ_{i≥1} Λ_i + h J_0ᵀ Φ_0. J_iᵀ x are
//             the model's transposed products (derivative_vjp, no matrix formed); each stage
//             system is solved by defect correction on a frozen factorisation of I − hγ J_ref
//             (J_ref by difference quotients, refreshed only when the correction stops
//             contracting below 0.3 per iteration), as the forward's Newton iteration is; it
//             stops when the correction is below 1e-12 of the solution.
//             A sample adds ∂g_k/∂y_k, through u̇_k = f_u(y_k) for accelerometers.
//   gradient  dJ/dc = h Σ_steps Σ_i Φ_iᵀ ∂f/∂c (t_i, Y_i) (+ the samples' u̇ share), chained to q
//             by ∂c/∂q: the gradient of the discrete J, exact up to the solvers' tolerances
//             (forward Newton 1e-10, stage systems 1e-12) and the central-difference φ-gradient
//             of J_r⁻¹ (~1e-10); one forward and one backward pass, whatever the number of
//             parameters.
//   Gauss–Newton matrix H = Σ_k τ_k S_kᵀ R S_k, S_k = ∂z_k/∂q by central differences of the
//             forward outputs (2 P forward runs, relative step 1e-4): an approximation of the
//             curvature only; the gradient is always the costate's.
// Memory: every step's stages are kept for the backward pass (steps × stages × 2 × state size
// doubles; no checkpointing yet).
#include <vector>

#include "scoleid/identify/fe/scole_nonlinear.h"
#include "scoleid/identify/inverse/measurements.h"
#include "scoleid/identify/inverse/misfit.h"
#include "scoleid/identify/inverse/objective.h"
#include "scoleid/identify/inverse/parameterization.h"
#include "scoleid/identify/time/nonlinear_forward.h"

namespace scoleid::identify {

struct NonlinearCostateSummary {
  long products = 0;             // transposed Jacobian and coefficient products
  long defect_iterations = 0;    // over all stage systems
  long jacobians = 0;            // J_ref refreshes
  double seconds = 0.0;
};

class NonlinearObjective : public Misfit {
public:
  // `weights` per sensor (empty: the relative default above).
  NonlinearObjective(const ScoleNonlinear& model, const Parameterization& params, std::vector<io::Signal> signals,
                     const Measurements& data, NonlinearForwardOptions forward = {},
                     std::vector<double> weights = {});

  int size() const override { return params_.size(); }
  double horizon() const override { return T_; }
  double data_start() const override { return data_.t.front(); }
  double data_end() const override { return data_.t.back(); }
  void set_horizon(double T) override;
  long data_points() const override;
  double cost(const VectorXd& q) override;
  double cost_and_gradient(const VectorXd& q, VectorXd& gradient) override;
  double gauss_newton(const VectorXd& q, VectorXd& gradient, MatrixXd& H, MisfitProfile* profile = nullptr) override;
  MisfitProfile misfit_profile(const VectorXd& q) override;
  VectorXd gauss_newton_product(const VectorXd& q, const VectorXd& v) override;
  bool has_matrix_free_products() const override { return false; }

  // The outputs at the samples on the horizon (samples × sensors).
  MatrixXd predict(const VectorXd& q);
  // ∂y/∂q at the samples on the horizon by central differences (relative step 1e-4), row
  // sample · sensors + sensor (objective.h's layout): 2P forward runs.
  MatrixXd output_sensitivities(const VectorXd& q);
  // dJ/dc for coefficients c directly (the gradient before the chain rule).
  double cost_and_coefficient_gradient(const VectorXd& c, VectorXd& gradient);
  const NonlinearForwardSummary& last_forward() const { return last_forward_; }
  const NonlinearCostateSummary& last_costate() const { return last_costate_; }
  // Solves and times over the objective's life (forward: every state run, sensitivity runs
  // included; costate: every backward pass; sensitivity: the difference runs of Gauss–Newton).
  const ObjectiveCounters& counters() const { return counters_; }
  const std::vector<double>& weights() const { return R_; }

private:
  int samples_on_horizon() const;
  NonlinearResponse forward(const VectorXd& c, bool keep_steps);
  double misfit_of(const NonlinearResponse& r) const;
  MisfitProfile profile_of(const NonlinearResponse& r) const;
  void reset_weights();

  const ScoleNonlinear& model_;
  const Parameterization& params_;
  std::vector<io::Signal> signals_;
  Measurements data_;  // a copy: the caller's may be a temporary (a half-record refit)
  NonlinearForwardOptions fopt_;
  std::vector<double> given_weights_, R_, tau_;
  double T_ = 0.0;
  NonlinearForwardSummary last_forward_;
  NonlinearCostateSummary last_costate_;
  ObjectiveCounters counters_;
};

}  // namespace scoleid::identify
