#pragma once
// An arm fixed to the mast's end section, turned exactly by the section's rotation
// (docs/theory.md §3.8, "The reflector's arm"). With θ = (θ_x, θ_y, ψ) the values of the section's
// linear rotation rows — θ⊥ = (θ_x, θ_y, 0) the slopes turned by 90°, so |θ⊥| is the sine of the
// tilt; ψ the twist about the mast's axis ẑ —
//   R(θ) = T(θ⊥) Z(ψ),   T = I + [θ⊥]× + [θ⊥]×² / (1 + √(1 − |θ⊥|²)),   Z = exp(ψ [ẑ]×),
// T being exp[α]× with α = θ⊥ asin|θ⊥| / |θ⊥| (the tilt that turns the axis onto the tangent), and
//   ρ(θ) = R(θ) r.
// Its derivatives in θ to the third: R separates, ∂_x^a ∂_y^b ∂_ψ^c R = (∂_x^a ∂_y^b T)(∂_ψ^c Z),
// T's from a Taylor polynomial in (θ_x, θ_y) truncated at degree 3 (every operation on it exact to
// that degree, √ and 1/x by their Taylor expansions about the current value), Z's in closed form.
// Regular for |θ⊥| < 1 (a tilt below 90°).
#include <Eigen/Dense>

#include <array>

namespace scoleid::identify {

struct TurnedArm {
  Eigen::Vector3d value = Eigen::Vector3d::Zero();  // ρ = R(θ) r
  Eigen::Matrix3d d1 = Eigen::Matrix3d::Zero();     // d1(i, k) = ∂ρ_i/∂θ_k
  std::array<Eigen::Matrix3d, 3> d2{};               // d2[i](k, l) = ∂²ρ_i/∂θ_k∂θ_l
  std::array<std::array<Eigen::Matrix3d, 3>, 3> d3{};  // d3[i][k](l, m) = ∂³ρ_i/∂θ_k∂θ_l∂θ_m
  bool has_third = true;                                // d3 computed (else zero)

  // ∂²ρ[a, b] = Σ_kl ∂²ρ/∂θ_k∂θ_l a_k b_l
  Eigen::Vector3d second(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;
  // ∇_θ (w · ∂ρ[b]) = Σ_i w_i ∂²ρ_i b
  Eigen::Vector3d second_t(const Eigen::Vector3d& b, const Eigen::Vector3d& w) const;
  // ∇_θ (w · ∂²ρ[a, a])
  Eigen::Vector3d third_t(const Eigen::Vector3d& a, const Eigen::Vector3d& w) const;
};

// R(θ) and its derivatives to the third, for turning several arms by one section's rotation
// (ρ is linear in r: each arm costs contractions only).
struct TurnedRotation {
  Eigen::Matrix3d value = Eigen::Matrix3d::Identity();
  std::array<Eigen::Matrix3d, 3> d1{};                              // ∂R/∂θ_k
  std::array<std::array<Eigen::Matrix3d, 3>, 3> d2{};               // ∂²R/∂θ_k∂θ_l
  std::array<std::array<std::array<Eigen::Matrix3d, 3>, 3>, 3> d3{};  // ∂³R/∂θ_k∂θ_l∂θ_m
  bool has_third = true;  // d3 computed (turned_rotation's `third`)
  TurnedArm arm(const Eigen::Vector3d& r) const;
};

// Both throw std::domain_error for |θ⊥| ≥ 1.
// Without `third`, d3 is left zero (and so are the arms' d3).
TurnedRotation turned_rotation(const Eigen::Vector3d& theta, bool third = true);
TurnedArm turned_arm(const Eigen::Vector3d& theta, const Eigen::Vector3d& arm);

}  // namespace scoleid::identify
