#pragma once
// Closed-form Euler–Bernoulli results used as references (uniform beam, length L, EI, ρA).
//
// Frequencies ω_k = (β_k L)² sqrt(EI / (ρA L⁴)), with β_k L the k-th positive root of
//   pinned–pinned    sin βL = 0                                  (β_k L = kπ)
//   clamped–free     1 + cos βL cosh βL = 0
//   free–free        1 − cos βL cosh βL = 0                       (flexible modes)
//   clamped–clamped  1 − cos βL cosh βL = 0
//   clamped, tip mass m_t and rotary inertia J_t at the free end (μ = m_t/(ρA L), j = J_t/(ρA L³)):
//     1 + c ch + μ λ (c sh − s ch) − j λ³ (s ch + c sh) + μ j λ⁴ (1 − c ch) = 0,  λ = βL
//     (Blevins, Formulas for Natural Frequency and Mode Shape, Table 8-1; c = cos, ch = cosh …)
// Roots are found by bracketing sign changes and bisection to machine precision.
//
// Static deflections: pinned–pinned with a point load P at a:
//   w(x) = P b x (L² − b² − x²) / (6 EI L),  x <= a,  b = L − a     (symmetric expression beyond a)
// clamped–free with a tip load P: w(x) = P x² (3L − x) / (6 EI).
//
// Step response of the pinned–pinned beam to a point step load P at a (zero initial state),
// modal series: w(x,t) = Σ_k (2P / (ρA L ω_k²)) sin(kπa/L) sin(kπx/L) (1 − cos ω_k t).
#include <string>
#include <vector>

#include "scoleid/io/scenario.h"

namespace scoleid::identify::analytic {

enum class Support { PinnedPinned, ClampedFree, FreeFree, ClampedClamped };

std::vector<double> beta_L(Support s, int count);
std::vector<double> beta_L_tip_mass(double mu, double j, int count);
// ω_k from β_k L
double omega(double betaL, double L, double EI, double rhoA);

// The first `count` nonzero natural frequencies ω [rad/s] of a uniform beam (one EI) with any end
// conditions, its tip body and its point elements (supports, attachments: masses, rotary inertias
// and springs; dashpots and ζ, c_kv ignored), exactly: the field z = (w, w_s, EI w_ss, EI w_sss)
// carried along each stretch between stations by the transfer matrix of the uniform beam at ω
// (Krylov–Duncan functions of β x, β⁴ = ρA ω²/EI), with the jumps a point element makes at its
// station (docs/theory.md §2.5):
//   [EI w_sss] = (m ω² − k_w − K_l(ω)) w(s_p),   [EI w_ss] = −(J ω² − k_θ) w_s(s_p),
// K_l(ω) = k_l (k_g − m_l ω²)/(k_l + k_g − m_l ω²) the dynamic stiffness of a lumped attachment
// (the determinant multiplied by its denominator, which only removes its poles),
// the left end's two free unknowns carried to the right end, whose two conditions vanish at a
// natural frequency. Carried in the scaled field (w, w_s/β, w_ss/β², w_sss/β³) in steps of β x <= 1,
// the two columns orthonormalised after each step (the determinant keeps its sign; unscaled, its
// terms of size e^{2βL} cancel and the high modes are lost). Roots by scanning for sign changes of
// the 2 × 2 determinant and bisection.
std::vector<double> point_element_omegas(const io::BeamSpec& beam, int count);

// The first `count` frequencies [Hz] of a beam with one EI from the closed forms above (its end
// conditions, a cantilever's tip body) or point_element_omegas (supports, attachments); empty for
// EI by sections or a tip body on other ends. `what` names the solution.
std::vector<double> beam_hz(const io::BeamSpec& beam, int count, std::string& what);

double ss_static_point_load(double x, double a, double P, double L, double EI);
double cantilever_static_tip_load(double x, double P, double L, double EI);
// Modal series with `terms` modes (the neglected tail is bounded by Σ k⁻⁴, below 1e-11 relative at 4000).
double ss_step_response(double x, double t, double a, double P, double L, double EI, double rhoA,
                        int terms = 4000);
// The same at t_k = k·dt, k = 0..n.
std::vector<double> ss_step_samples(double x, double dt, int n, double a, double P, double L, double EI, double rhoA,
                                    int terms = 4000);
// The same for a scenario: a uniform simply supported beam under its first input's step load
// (its value at t = 1), at its first sensor and sample times (std::invalid_argument otherwise).
std::vector<double> ss_scenario_samples(const io::Scenario& sc, int terms = 4000);

}  // namespace scoleid::identify::analytic
