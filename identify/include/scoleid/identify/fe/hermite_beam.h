#pragma once
// Euler–Bernoulli beam element with Hermite cubic shape functions (C¹), DOFs (w, θ = w_s) at
// each end. On an element of length h with ξ = (s − s_a)/h ∈ [0, 1]:
//   N1 = 1 − 3ξ² + 2ξ³,   N2 = h (ξ − 2ξ² + ξ³),   N3 = 3ξ² − 2ξ³,   N4 = h (ξ³ − ξ²)
// Weak forms integrated over [s_a, s_b] ⊂ element with a coefficient constant on that piece:
//   mass      ∫ N Nᵀ ds              (consistent; × ρA)
//   stiffness ∫ N'' N''ᵀ ds          (× EI; the Kelvin–Voigt damping uses the same matrix)
//   slope     ∫ N' N'ᵀ ds            (× d; the square-root (Chen–Russell) damping, docs/theory.md §2.2;
//                                     on a whole element (1/(30h)) [[36, 3h, −36, 3h], [3h, 4h², −3h, −h²],
//                                     [−36, −3h, 36, −3h], [3h, −h², −3h, 4h²]], the "geometric stiffness")
// Integration is by Gauss–Legendre, exact for these polynomial degrees, so a coefficient that
// jumps inside an element (sections not aligned with the mesh) is integrated exactly too.
// Frequencies converge as O(h⁴) (verified in tests/identify/hermite_beam_test.cpp).
#include <Eigen/Dense>

namespace scoleid::identify::hermite {

using Mat4 = Eigen::Matrix4d;
using Vec4 = Eigen::Vector4d;

Vec4 shape(double xi, double h);     // N
Vec4 slope(double xi, double h);     // dN/ds
Vec4 curvature(double xi, double h); // d²N/ds²

// ∫_{a}^{b} N Nᵀ ds and ∫ N'' N''ᵀ ds over the piece [a, b] of an element of length h
// (a, b measured from the element's left end, 0 <= a < b <= h).
Mat4 mass(double h, double a, double b);
Mat4 stiffness(double h, double a, double b);
// ∫_{a}^{b} N' N'ᵀ ds over the same piece.
Mat4 slope_product(double h, double a, double b);

}  // namespace scoleid::identify::hermite
