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
#include "scoleid/identify/inverse/objective.h"

namespace scoleid::identify {

struct CvodesAdjointResult {
  double cost = 0.0;
  VectorXd gradient;
  long forward_steps = 0, backward_steps = 0;
};

CvodesAdjointResult cvodes_adjoint_gradient(Objective& objective, const VectorXd& q, double rtol = 1e-10);

}  // namespace scoleid::identify
