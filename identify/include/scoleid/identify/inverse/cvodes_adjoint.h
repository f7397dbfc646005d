#pragma once
// Independent reference gradient by the SUNDIALS CVODES adjoint module (CVodeF / CVodeB) on
// the same semi-discrete FE ODE, written as a first-order system y = [x; v]:
//
//   ẏ = f(t, y, q) = [v; a],  a = M⁻¹(B f(t) − D v − K x),     G(q) = ∫ g dt,  g = ½ rᵀ R r,
//   r = C0 x + C1 v + C2 a − z̃   (rows on displacements, velocities and accelerations; docs/theory.md §6.1a)
//   λ̇ = −f_yᵀ λ − g_yᵀ,  λ(T) = 0,   f_yᵀ λ = [−K M⁻¹ λ_v;  λ_x − D M⁻¹ λ_v],
//   g_yᵀ = [C0ᵀ R r − K ν;  C1ᵀ R r − D ν],  ν = M⁻¹ C2ᵀ R r
//   dG/dq_i = ∫ (λᵀ ∂f/∂q_i + ∂g/∂q_i) dt = −qB_i(t0)   (quadrature integrated from T back to t0),
//   ∂f/∂q_i = [0; M⁻¹ h_i],  ∂g/∂q_i = νᵀ h_i,  h_i = ∂B f − ∂D v − ∂K x − ∂M a.
// Dense matrices and difference-quotient Jacobians: for verification on small meshes only.
// It shares nothing with the costate code but the assembled operators.
#include "scoleid/identify/fe/scole_nonlinear.h"
#include "scoleid/identify/inverse/objective.h"

namespace scoleid::identify {

struct CvodesAdjointResult {
  double cost = 0.0;
  VectorXd gradient;
  long forward_steps = 0, backward_steps = 0;
};

CvodesAdjointResult cvodes_adjoint_gradient(Objective& objective, const VectorXd& q, double rtol = 1e-10);

// The nonlinear SCOLE model (fe/scole_nonlinear.h) with the sampled cost of nonlinear_objective.h,
// J = ½ Σ_k τ_k Σ_j R_j (z_j(y(t_k)) − z̃_kj)² (trapezoid τ_k over data.t, weights R_j given), on
// the continuous-time ODE ẏ = f(t, y; c) from rest: CVODES BDF forward, and backward the adjoint
//   λ̇ = −f_yᵀ λ between samples,  λ(t_k⁻) = λ(t_k⁺) + ∂g_k/∂y_k  at each sample (CVodeReInitB),
//   dJ/dc = ∫ λᵀ ∂f/∂c dt + Σ_k ∂g_k/∂c   (the latter through u̇ for accelerometers).
// It shares the model's transposed products with the discrete costate (checked against
// differences on their own), not its time discretisation or its recursion: the two gradients
// differ by the ESDIRK stepping's error.
CvodesAdjointResult cvodes_nonlinear_gradient(const ScoleNonlinear& model, const VectorXd& c,
                                              const std::vector<io::Signal>& signals, const Measurements& data,
                                              const std::vector<double>& weights, double rtol = 1e-10);

}  // namespace scoleid::identify
