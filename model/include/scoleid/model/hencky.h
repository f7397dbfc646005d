#pragma once
// Hencky bar-chain lumping of a beam (or a torsion rod) into n rigid segments.
//
// Physics. A rigid bar of length h = L/n carries its own distributed mass rho_A h at its centre
// with rotary inertia rho_A h^3/12, so its kinetic energy is that of linear (consistent-mass)
// interpolation between its end joints. Joint j sits at s_j = j h (j = 0..n). The joint angle
// phi_j = theta_{j+1} - theta_j is h times the central second difference of w, so a joint spring
//
//     k_j = 1 / integral over the joint's dual cell of ds / EI(s),
//     dual cell = [s_j - h/2, s_j + h/2] intersected with [0, L],
//
// stores the strain energy of that cell, 1/2 EI w''^2 h, to O(h^2). For a uniform beam this is
// EI/h at interior joints and 2EI/h at a clamped end joint (the half cell is the mirror-image
// "ghost point" of the clamped boundary); pinned and free ends carry no spring. Piecewise EI is
// handled by the same integral (series compliance), so section boundaries need not fall on
// joints. The Kelvin–Voigt term (c w_sst)_ss (for the beam c = c_kv, one value) lumps the same
// way into joint dampers c_j = 1 / integral over the cell of ds / c(s). (The beam's square-root
// damping -(d w_st)_s acts on the bars' rotations, not on the joints: beam_chain.h.) The torsion rod GJ psi_ss is the second-order analogue: segment polar inertia
// rho_I_psi h, joint springs GJ/h, 2GJ/h at a clamped end.
//
// The result is the central-difference analogue of the PDE: natural frequencies converge
// O(h^2) = O(1/n^2) (tests/model/hencky_test.cpp measures the rate). Lumping EI/h at the clamped
// joint instead of 2EI/h, or point masses at segment centres, gives O(1/n).
#include <vector>

namespace scoleid::model {

// A field on [0, length] that is constant on `values.size()` equal sections.
struct PiecewiseField {
  double length = 1.0;
  std::vector<double> values = {1.0};

  double at(double s) const;
  // Exact integral of 1/f over [a, b] (0 <= a <= b <= length).
  double integral_of_inverse(double a, double b) const;
};

struct HenckyLumping {
  int segments = 0;
  double h = 0.0;
  // Joint j at s = j h, j = 0..segments. Interior joints are always filled; the end joints
  // (0 and segments) hold the clamped-end value, which the caller uses only for a clamped end.
  std::vector<double> stiffness;
  std::vector<double> damping;
};

// `rigidity` is EI(s) (or GJ(s)); `damping_coefficient` is c(s) (all zero for no damping).
HenckyLumping hencky_lumping(int segments, const PiecewiseField& rigidity,
                             const PiecewiseField& damping_coefficient);

}  // namespace scoleid::model
