#pragma once
// The step of trust-region Gauss–Newton on x = log q.
//
// Model of the cost about x:  m(δ) = J + gᵀδ + ½ δᵀ H δ,  H = Sᵀ R S ⪰ 0 (Gauss–Newton matrix).
// Step: the minimiser of m over ‖δ‖₂ <= Δ,
//     δ(λ) = −(H + λ I)⁻¹ g,   λ = 0 if the Gauss–Newton step fits, else the λ > 0 with ‖δ(λ)‖ = Δ
// (Levenberg; Moré & Sorensen), computed from the eigendecomposition H = V diag(μ) Vᵀ:
// ‖δ(λ)‖² = Σ (vᵢᵀg)² / (μᵢ + λ)² falls monotonically with λ, so λ follows by bisection in log λ.
// The damping is λ I in log q, not λ diag H (Marquardt): a direction the data barely see (tiny μ)
// is damped hardest, relative to its curvature, and does not make the well-determined directions
// wait — with λ diag H a parameter with a small diagonal would need a huge λ to keep its own step
// in the region, shortening every other step with it.
//
// Radius (Nocedal & Wright, Alg. 4.1): with ρ = (J − J_new) / (m(0) − m(δ)) the ratio of actual to
// predicted decrease, Δ ← ‖δ‖/4 if ρ < 1/4; Δ ← min(2Δ, Δ_max) if ρ > 3/4 and the step reached the
// boundary. A step is accepted when J_new < J. When ρ is well above 1 the model's curvature along
// δ is too large (a curved valley, a large residual) and plain Gauss–Newton would creep; the
// optimiser then tries 2δ, 4δ, … while the cost keeps falling (optimizers.h).
#include <Eigen/Dense>

namespace scoleid::identify {

struct TrustRegionStep {
  Eigen::VectorXd delta;
  double lambda = 0.0;
  double predicted = 0.0;  // m(0) − m(δ) >= 0
  bool on_boundary = false;
};

TrustRegionStep trust_region_step(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, double radius, double lambda_min = 0.0);

// New radius after a trial step with actual/predicted ratio rho.
double update_radius(double radius, const TrustRegionStep& step, double rho, double max_radius);

}  // namespace scoleid::identify
