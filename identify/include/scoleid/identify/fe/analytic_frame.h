#pragma once
// The exact sway frequencies of the frame of docs/theory.md §2.6 (undamped), free of the finite
// elements: each storey's columns solved in closed form between their ends.
//
// A column (EI, ρA, height h) held from turning at both ends and swaying u1 at its foot and u2 at
// its head, at frequency ω, is w(x) = a S + b T + c U + d V in the Krylov functions of z = βx,
// β⁴ = ρA ω²/EI (S, T, U, V the sums of z^(4k+i)/(4k+i)!, i = 0..3: no cancellation at small z);
// its end shears F1 = EI w'''(0), F2 = −EI w'''(h) give the 2 × 2 dynamic stiffness, whose static
// limit is 12EI/h³ [[1, −1], [−1, 1]]. Assembled on the floors' sways with −ω² m_k, the frame's
// frequencies are the roots of its determinant. Below the first clamped–clamped column frequency
// (4.730² √(EI/ρA)/h², where the dynamic stiffness has its first pole) the determinant is smooth;
// there the number of D(ω)'s negative eigenvalues counts the frame's frequencies below ω
// (Wittrick–Williams), and each is found by bisection on that count (no root can be missed).
#include <Eigen/Dense>
#include <vector>

#include "scoleid/io/scenario.h"

namespace scoleid::identify::analytic {

// The 2 × 2 dynamic stiffness of one column (end forces for end sways).
Eigen::Matrix2d column_dynamic_stiffness(double EI, double rho_A, double h, double omega);
// det of the floors' dynamic stiffness at ω.
double frame_determinant(const io::FrameSpec& frame, double omega);
// The number of the frame's sway frequencies below ω (< the first column pole).
int frame_modes_below(const io::FrameSpec& frame, double omega);
// The sway frequencies ω [rad/s] below the first column pole, ascending, at most `count`.
std::vector<double> frame_omegas(const io::FrameSpec& frame, int count);

}  // namespace scoleid::identify::analytic
