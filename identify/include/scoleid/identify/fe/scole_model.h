#pragma once
// Finite-element model of SCOLE (docs/theory.md §3, §4.3) for the identifier, in the form of
// structural_model.h: linearised about the undeformed configuration, small motions, free-floating
// (no gravity), slug–ft–s. Shuttle frame S: x roll, y pitch, z yaw, origin at the shuttle CM; the
// mast leaves the shuttle at r0 = mast_root along −z, s ∈ [0, L], undeformed p(s) = r0 − s e_z.
//
// Absolute (inertial) coordinates, so every operator is the plain FE operator of its field:
//   shuttle    X, Y, Z (CM translation), θ = (θx, θy, θz) small rotation;  KE ½ m1|Ẋ|² + ½ θ̇ᵀ I1 θ̇
//   mast       u_x(s), u_y(s) absolute lateral displacements, Hermite cubics (value, slope);
//              ψ(s) torsion about z, linear (C0) elements. Inextensible: the axial displacement is
//              the shuttle's rigid one, w = Z + θx r0_y − θy r0_x (the mast's mass moves with it).
//   cross-section rotation (small, in S):  Θ(s) = (u_y'(s), −u_x'(s), ψ(s))
//              (the tangent (u_x', u_y', −1) is e = −e_z turned by Θ: Θ × e = (−Θy, Θx, 0)).
//   root       clamped to the shuttle:  u(0) = X + θ × r0,  Θ(0) = θ, i.e.
//              u_x(0) = X + θy r0_z − θz r0_y,  u_x'(0) = −θy,
//              u_y(0) = Y + θz r0_x − θx r0_z,  u_y'(0) = θx,   ψ(0) = θz.
//              The root DOFs are eliminated by u_full = T u (M = Tᵀ M_full T, …).
//   energies   T = ½ ρA ∫ (u̇_x² + u̇_y² + ẇ²) ds + ½ ρI_ψ ∫ ψ̇² ds
//                  + ¼ ρI_ψ ∫ (Θ̇x² + Θ̇y²) ds   (the section's bending rotary inertia ρI_ψ/2 per
//                  plane, Rayleigh beam; only with scole.bending_rotary_inertia),
//              V = ½ EI_pitch ∫ u_x''² + ½ EI_roll ∫ u_y''² + ½ GJ ∫ ψ'².
//              Curvatures and twist rate of the absolute fields are those of the deformation
//              relative to the shuttle (rigid motions are linear in s for u, constant for ψ), so
//              K has the six rigid-body modes of the free-floating system in its null space.
//              Roll bending is u_y (EI_roll), pitch bending u_x (EI_pitch).
//   damping    ζ dimensionless (docs/theory.md §3.3). Bending: square-root (Chen–Russell) damping on
//              the slope rate relative to the shuttle, dissipation ½ d_roll ∫ (Θ̇x − θ̇x)² +
//              ½ d_pitch ∫ (Θ̇y − θ̇y)², d = 2ζ√(ρA EI) (the PDE term −2ζ√(ρA·EI) u_sst: ratio ζ in
//              every mode of a uniform pinned beam; rigid motion undamped). Torsion: Kelvin–Voigt
//              c_tors K1_ψ, c_tors = 2ζ√(ρI_ψ GJ)·2L/π (ratio ζ in the first clamped–free mode).
//   reflector  rigid, welded at s = L, CM at r = (r_x, r_y, 0) from the tip (shuttle axes):
//              CM displacement  u_R = u(L) + Θ(L) × r,  rotation Θ(L);
//              KE ½ m4 |u̇_R|² + ½ Θ̇ᵀ I4 Θ̇ (I4 about its CM): a constant mass term coupling
//              torsion to both bending planes (docs/theory.md §3.2: f_φ,4 = −m4 (ü_y(L) + r_x ψ̈(L)) + F_y).
//   proof mass k at s_k (massless carriage on a slider along x, the mass on a slider along y —
//              model/scole_system.cpp): DOFs are its absolute lateral position ξ_k = (ξx, ξy);
//              axially it moves with the mast. KE ½ m_k (ξ̇x² + ξ̇y² + ẇ²); on each slider a
//              centering spring k_a and damper c_a act on the stroke ξ − u(s_k) (§3.7):
//              V += ½ k_a |ξ − u(s_k)|², dissipation ½ c_a |ξ̇ − u̇(s_k)|². With k_a = 0 (the free
//              slider) K has 6 + 2·(actuators) zero eigenvalues and an unforced proof mass does not
//              load the mast laterally.
// Coefficients c = [ρA, EI_roll, EI_pitch, GJ, ρI_ψ, d_roll, d_pitch, c_tors, m_reflector,
// k_actuator, c_actuator]; the
// reflector's translational mass is its own term (so m_reflector can be estimated); the shuttle,
// the reflector's rotary inertia and the proof masses are constant terms (coefficient −1).
//
// DOF order (M + γD + γ²K banded with a dense border, time/banded_cholesky.h): nodes 1..n,
// each (u_x, u_x', u_y, u_y', ψ), the proof masses' (ξx, ξy) right after the node nearest them;
// then the shuttle's X, Y, Z, θx, θy, θz, which couple to the first node (root), to the tip
// (reflector offset, the bending damping's relative slopes) and to each other.
//
// Inputs (model/inputs.cpp resolve_inputs/InputForces: f(t) d, d a unit direction in S; the
// linearisation drops R_GS ≈ I + θ×, second order with f):
//   shuttle  force at its CM: b = d on (X, Y, Z);   moment: b = d on θ
//   reflector force at its CM (reflector_station = the CM): b = (∂u_R/∂u)ᵀ d;  moment: (∂Θ(L)/∂u)ᵀ d
//   mast     force at station s: b = (∂(u_x, u_y, w)(s)/∂u)ᵀ d;  moment: (∂Θ(s)/∂u)ᵀ d
//   actuatorK (force only, d in the x–y plane): slider generalized forces f d_x, f d_y on the
//            relative coordinates ξ − u(s_k): b = d_x (e_ξx − ∂u_x(s_k)/∂u) + d_y (e_ξy − ∂u_y(s_k)/∂u).
//            f is the commanded force itself: the model has no servo lag (build_scole refuses
//            scole.actuator_lag > 0; the truth models it under truth.overrides.scole).
// Sensors (model/sensors.cpp read_sensor, reference body R = shuttle):
//   displacement  (p_RP − p_RP0)·d, linearised: (δp_P − X − θ × p_P0)·d  (mast station or reflector CM)
//   rotation      θ_RB·d = (Θ_B − θ)·d, Θ_B = Θ(s) on the mast, Θ(L) for the reflector
//   line_of_sight (u0 × u)·d, u, u0 unit vectors root→P: linearised (u0 × δp_rel)·d / |p_P0 − r0|
//   at: shuttle   (R = ground): displacement X·d, rotation θ·d
//   velocity      d/dt of the displacement quantity (relative; the shuttle's CM in ground): its row on u̇
//   acceleration  inertial acceleration of the point along d (an accelerometer): the absolute
//                 displacement's row (u_x, u_y, w)(s), u_R or the shuttle CM, on ü
#include <memory>
#include <string>
#include <vector>

#include "scoleid/identify/inverse/physical_parameterization.h"
#include "scoleid/identify/fe/structural_model.h"
#include "scoleid/identify/fe/structure.h"
#include "scoleid/io/scenario.h"

namespace scoleid::identify {

struct ScoleFE {
  StructuralModel model;
  io::ScoleSpec spec;
  int elements = 0;

  enum Coefficient {
    kRhoA = 0, kEIRoll, kEIPitch, kGJ, kRhoIPsi, kDRoll, kDPitch, kCTors, kMReflector, kKActuator, kCActuator, kCount
  };
  // Field of a mast node DOF.
  enum Field { kUx = 0, kUxSlope, kUy, kUySlope, kPsi };

  // Reduced index of a shuttle DOF (0..5: X, Y, Z, θx, θy, θz), of a mast node field (−1 at
  // node 0, which is eliminated) and of proof mass k's ξx, ξy (axis 0, 1).
  int shuttle_dof(int i) const { return shuttle_reduced[static_cast<std::size_t>(i)]; }
  int node_dof(int node, Field f) const;
  int proof_mass_dof(int k, int axis) const { return proof_reduced[static_cast<std::size_t>(2 * k + axis)]; }

  // Rows (3 × ndof) on the reduced DOF vector.
  MatrixXd mast_displacement(double s) const;  // absolute (u_x, u_y, w)(s)
  MatrixXd mast_rotation(double s) const;      // absolute Θ(s)
  MatrixXd reflector_displacement() const;     // absolute u_R
  MatrixXd shuttle_rigid_displacement(const Eigen::Vector3d& p0) const;  // X + θ × p0
  MatrixXd shuttle_rotation() const;           // θ
  // The reduced DOF vector of a rigid motion of the whole system: translation a, rotation θ
  // (about the shuttle CM); proof masses move with it.
  VectorXd rigid_motion(const Eigen::Vector3d& a, const Eigen::Vector3d& theta) const;

  // Layout (filled by build_scole). The full vector holds X, Y, Z, θx, θy, θz, then 5 DOFs per
  // node 0..n, then (ξx, ξy) per proof mass; u_full = T u.
  int nfull = 0;
  SparseMatrix T;
  std::vector<int> shuttle_reduced, proof_reduced;
  std::vector<int> node_reduced;  // 5 per node: reduced index, −1 at node 0
};

// Inputs and sensors as described above, a validated scenario's (io::validate_scenario, SCOLE's
// KindTable::check); anything else is a std::logic_error.
ScoleFE build_scole(const io::ScoleSpec& scole, int elements, const std::vector<io::InputSpec>& inputs,
                    const std::vector<io::SensorSpec>& sensors);

// Coefficients c for the physical values of a ScoleSpec.
VectorXd scole_coefficients(const io::ScoleSpec& s);

// SCOLE's parameter space (physical_parameterization.h): φ = [ρA, EI_roll, EI_pitch, GJ, ρI_ψ, ζ,
// m_reflector, k_actuator, c_actuator], the group EI (both bending planes), the paper form q1 = EI/ρA, q2 = 1/ρA (the
// bending equations divided by ρA).
ParameterSpace scole_parameter_space(const io::ScoleSpec& scole);

// The identifier's view of a scole scenario (fe/structure.h); make_structure's registry row.
std::unique_ptr<FEStructure> make_scole_structure(const io::Scenario& sc, int elements);

}  // namespace scoleid::identify
