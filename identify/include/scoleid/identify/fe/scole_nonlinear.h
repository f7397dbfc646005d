#pragma once
// Nonlinear SCOLE for large slews (docs/theory.md §3.8): the shuttle turns through finite
// angles, the mast's elastic deflection stays small and is measured in the shuttle's rotating
// frame S (a floating frame of reference), with the inertial coupling of that frame's motion.
//
// Coordinates  q = (X, φ, e): X the shuttle CM in ground, φ the rotation vector of R = R_GS
//              (rotation_vector.h), e the elastic DOFs: the linear model's DOF vector
//              (scole_model.h) without its six shuttle entries, i.e. the node fields
//              (u_x, u_x', u_y, u_y', ψ) and the proof masses' lateral positions, all relative to S.
// Speeds       u = (V, Ω, ė): V = Rᵀ Ẋ the CM velocity in S, Ω the body angular velocity.
// Kinematics   Ẋ = R V,  φ̇ = J_r(φ)⁻¹ Ω,  d(e)/dt = ė.
// Mass points  (Kane's equations) m_i at r_i = p_i + N_i e in S (p_i undeformed, N_i the linear
//              model's displacement rows on e):  velocity v_i = V + Ω × r_i + N_i ė = L_i u,
//              L_i = [I, −[r_i]×, N_i];  inertial acceleration in S  a_i = L_i u̇ + γ_i,
//              γ_i = Ω × V + Ω × (Ω × r_i) + 2 Ω × N_i ė  (transport, centrifugal, Coriolis).
//              The mast's ρA by four Gauss points per element (exact for the Hermite consistent
//              mass), the reflector, the proof masses' CMs, the shuttle's CM.
//              Some points are nonlinear in e (struct Kinematics): a proof mass, whose slider
//              plane turns with the section, r = p + N e + Θ(s_k) e × (stroke), and the
//              reflector's points. The reflector is a rigid body on the mast's end: its CM (its
//              mass) and pairs of points on the principal axes of its second moment (its inertia),
//              each at an arm turned exactly with the end section (R = exp[α] exp[ψ ẑ],
//              turned_arm.h) and carried back by the end's foreshortening ½ ∫ (u_x'² + u_y'²) ds.
//              For them N_i becomes N_i(e) = ∂r_i/∂e and γ_i gains the convective term r''[ė, ė]
//              (d²r/dt² = N(e) ë + r''[ė, ė]); M_ee then
//              depends on e (factorised per e on a fixed sparse pattern; the foreshortening's dense
//              rank-2 part by the Woodbury identity). The mast's own points keep r = p + N e and
//              carry their foreshortening w = ½ eᵀ Q(s) e through the kinetic energy: the cross
//              term Σ m (V + Ω × r + N ė)·(t ẇ + (Ω × t) w) (rigid rows of M and b) and the axial
//              inertia Σ ½ m ẇ² (M_ee += Σ m g gᵀ, g = Q e: dense, by conjugate gradients
//              preconditioned with the rest of M) (struct Foreshortening).
//              A force at the reflector's CM and an accelerometer there use its r(e), N(e).
// Rotors       inertia J_j turned by the section's rotation R to second order in θ = Θ_j e,
//              J(θ) = R J_j Rᵀ + O(θ³) (quadratic in θ; its second-order part is the centrifugal
//              stiffness of a body turned in a spinning frame; docs/theory.md §3.8),
//              ω_j = Ω + Θ_j(e) ė = L_j(e) u, L_j = [0, I, Θ_j(e)]
//              (Θ_j the linear model's rotation rows, Θ_j(e) its second-order angular velocity on
//              the mast, struct Rotor); kinetic energy T = ½ ω_jᵀ J(θ) ω_j, whose generalized
//              inertia force (Boltzmann–Hamel on Ω, Lagrange on e) is L_jᵀ (J(θ) ω̇ + J̇ ω) +
//              [0; Ω × J(θ) ω; Θ̇(e)ᵀ h − (∂ω/∂e)ᵀ h − Θᵀ ∂T/∂θ], h = J(θ) ω,
//              J̇ ω = ∂J/∂θ[θ̇] ω, ∂T/∂θ = ½ ∇_θ (ωᵀ J(θ) ω) (first order: θ̇ × J ω − J (θ̇ × ω) and
//              J ω × ω): the gyroscopic coupling of the slew's rate with an anisotropic rotor's
//              elastic rotation.
//              The shuttle (no elastic rotation) and the section's ρI_ψ (three Gauss points per
//              element). Energy and momenta are conserved exactly.
// Strain       the linear model's ½ eᵀ K e and the mast's W₃ + W₄ (struct Coupling): the
//              Kirchhoff rod's energy to fourth order in the deflection.
// Equations    M(e) u̇ + b(u, e) + [0; 0; D ė + K e + ∇W(e)] = Q(t, e),
//              M = Σ m_i L_iᵀ L_i + Σ L_jᵀ J(θ_j) L_j + M_fs,   b = Σ m_i L_iᵀ γ_i + the rotors' terms
//              + the foreshortening's (struct Foreshortening),
//              K, D the linear model's elastic blocks (they see only the deformation relative
//              to S), every term affine in the coefficients c (scole_model.h), so ∂/∂c_k of the
//              residual is the residual of c = e_k without the constant terms.
// Inputs       f(t) d with d fixed in S, as the truth applies them: shuttle force/moment, mast or
//              reflector moment, actuator slider forces: the linear model's generalized load
//              G ᵀb (G maps (X, θ, e) to the linear DOFs); a force at a mast station or the
//              reflector CM also turns with its arm: Q_Ω = (p + N e) × d f.
// Sensors      shuttle rotation φ·d (the truth's angle–axis read-out while the angle stays below π,
//              where the truth's wraps), shuttle displacement X·d, velocity
//              (R V)·d, acceleration (R (V̇ + Ω × V))·d, all in ground; mast and reflector
//              displacement, rotation, line of sight and velocity: the linear model's rows on e
//              or ė (relative to S, in S); an acceleration: the point's inertial acceleration in
//              S along d, a_i · d.
// At rest (q = 0, u = 0) the linearisation is the linear model in the coordinates (X, θ, e):
// M(0) = Gᵀ M_lin G, the same K, D, loads and sensor rows.
//
// Implemented in identify/fe/scole_nonlinear/, one part per file: kinematics (rows, a point's and
// a rotor's motion with the section), assembly (the bodies' mass points and rotors, inputs,
// sensors), foreshortening, dynamics (coupling energy, rigid and foreshortening rows), mass (the
// mass matrix and its solves) and equations (residual, Jacobians, products, outputs).
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/SparseCholesky>

#include "scoleid/identify/fe/scole_model.h"
#include "scoleid/identify/fe/turned_arm.h"

namespace scoleid::identify {

class ScoleNonlinear {
public:
  // Built on the linear model's discretisation of the same scenario (the same elements,
  // inputs and sensors, in the same order).
  ScoleNonlinear(const ScoleFE& fe, const std::vector<io::InputSpec>& inputs,
                 const std::vector<io::SensorSpec>& sensors);

  int elastic() const { return ne_; }            // dim e
  int speeds() const { return 6 + ne_; }         // dim u
  int state_size() const { return 12 + 2 * ne_; } // y = [X, φ, e, V, Ω, ė]
  int inputs() const { return static_cast<int>(inputs_.size()); }
  int sensors() const { return static_cast<int>(sensors_.size()); }
  int coefficients() const { return ncoef_; }
  const std::vector<std::string>& sensor_names() const { return sensor_names_; }

private:
  // A point whose position is nonlinear in e (the proof masses, the reflector's points), on the union
  // of the columns its rows touch (x̂ = x on them):
  //   r(e) = p + N e + (A ê) × (B ê) + t ½ êᵀ Q ê + [ρ(Θ ê) − a − (Θ ê) × a],
  // a quadratic part — a proof mass on a slider plane that turns with the section: A the section's
  // rotation rows, B the stroke's; an axial part t ½ êᵀ Q ê, the foreshortening of a point at the
  // mast's end (Q = ∫ Θ⊥ᵀ Θ⊥ ds over the mast, t the unit vector back towards the root) — and a
  // turned arm a (Θ the end section's rotation rows, ρ = R(θ) a exactly: turned_arm.h; its linear
  // part θ × a is in N). Empty A, B, Q or Θ for none. The point's map at one e (struct At):
  //   N(e) = ∂r/∂e = N + [A ê]× B − [B ê]× A + t (Q ê)ᵀ + (∂ρ + [a]×) Θ,
  //   d²r/dt² = N(e) ë + r''[ė, ė],   r''[x, y] = (A x̂) × (B ŷ) + (A ŷ) × (B x̂) + t x̂ᵀ Q ŷ + ∂²ρ[Θ x̂, Θ ŷ].
  struct Kinematics {
    std::vector<int> cols;
    std::vector<char> local;  // per column: touched by N, A, B or Θ (not only by Q)
    std::vector<int> local_index;  // the positions in cols of the local columns
    Eigen::Matrix<double, 3, Eigen::Dynamic> N, A, B, Theta;
    SparseMatrix P;  // Q = Pᵀ P (the slopes' rows at Gauss points, times √weight); empty for none
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    Eigen::Vector3d arm = Eigen::Vector3d::Zero();
    bool active() const { return !cols.empty(); }
    bool axial() const { return P.rows() != 0; }
    VectorXd gather(const VectorXd& x) const;
    struct At {
      const Kinematics* k = nullptr;
      VectorXd g;                                  // ê
      TurnedArm turned;                            // ρ at θ = Θ ê (with an arm)
      Eigen::Vector3d offset;                      // r(e) − p − N e
      Eigen::Matrix<double, 3, Eigen::Dynamic> J;  // N(e) on cols
      VectorXd Qg;                                 // Q ê (with an axial part)
      Eigen::Vector3d rows(const VectorXd& y) const;                          // (N(e) − N) y
      void rows_t(const Eigen::Vector3d& w, VectorXd& out) const;             // out += (N(e) − N)ᵀ w
      Eigen::Vector3d convective(const VectorXd& x) const;                    // r''[x, x]
      // out += ∇_e (w · N(e) y) = r''[·, y]ᵀ w. With `axial`, the axial part's (t·w) Q ŷ is left
      // to the caller: (t·w) ŷ is added to *axial (on cols), for one add_axial of the sum.
      void second_t(const VectorXd& y, const Eigen::Vector3d& w, VectorXd& out, VectorXd* axial = nullptr) const;
      // out += ∇_e (w · r''[x, x]) at fixed x (zero without an arm: the rest is quadratic)
      void convective_t(const VectorXd& x, const Eigen::Vector3d& w, VectorXd& out) const;
    };
    // With the section's rotation R(Θ ê) when the caller already has it (points sharing Θ).
    At at(const VectorXd& e, const TurnedRotation* turned = nullptr, bool third = true) const;
    // out += Q ẑ on cols (z on cols).
    void add_axial(const VectorXd& z, VectorXd& out) const;
    int axial_group = -1;  // points with the same cols and P share one (ScoleNonlinear::axial_rep_)
  };

public:

  // The operators at coefficients c. `constants` scales the terms without a coefficient (1 for
  // the model; 0 with c = e_k gives ∂/∂c_k of the residual, the loads excluded).
  class Dynamics {
  public:
    const ScoleNonlinear& model() const { return *g_; }
    MatrixXd mass(const VectorXd& e) const;
    // b(u, e) + [0; 0; D ė + K e]
    VectorXd internal(const VectorXd& u, const VectorXd& e) const;
    // Q(t, e) for the input values f_i(t).
    VectorXd load(const VectorXd& f, const VectorXd& e) const;
    // ẏ for input values f; u̇ returned in `udot` if given.
    void derivative(const double* y, const VectorXd& f, double* ydot, VectorXd* udot = nullptr) const;
    // The residual R = M u̇ + internal − Q at a state and u̇ (zero on the motion).
    VectorXd residual(const double* y, const VectorXd& udot, const VectorXd& f) const;
    // Sensor read-outs at a state, u̇ the accelerations there.
    VectorXd outputs(const double* y, const VectorXd& udot) const;
    // Products with the transposed derivatives (for the costate, docs/theory.md §6.7), at a state y
    // with input values f and ydot = f(t, y) already evaluated:
    //   (∂f/∂y)ᵀ λ,   and λᵀ ∂f/∂c (one entry per coefficient).
    VectorXd derivative_vjp(const double* y, const VectorXd& f, const VectorXd& ydot, const VectorXd& lambda) const;
    VectorXd coefficient_vjp(const double* y, const VectorXd& f, const VectorXd& ydot, const VectorXd& lambda) const;
    // ρᵀ z(y, u̇) differentiated: ∂/∂y at fixed u̇ (dy) and ∂/∂u̇ (da).
    void outputs_vjp(const double* y, const VectorXd& udot, const VectorXd& rho, VectorXd& dy, VectorXd& da) const;
    // Kinetic + strain energy, linear momentum and angular momentum about the ground origin.
    double energy(const double* y) const;
    Eigen::Vector3d momentum(const double* y) const;
    Eigen::Vector3d angular_momentum(const double* y) const;

  private:
    friend class ScoleNonlinear;
    // s = μᵀ R(y, a) (R the residual at accelerations a): ∂s/∂e, ∂s/∂u, and per coefficient
    // ∂s/∂c_k (the loads' coefficient-free part excluded).
    // kin: kinematics(e, true) at the state's e.
    void residual_vjp(const double* y, const VectorXd& a, const VectorXd& mu, const VectorXd& f, VectorXd& de,
                      VectorXd& du, VectorXd* dc, const std::vector<Kinematics::At>& kin) const;
    // Its parts: the mass points, the rotors, the loads (ds/dė gathered in due).
    struct VjpFrame;
    void add_points_vjp(const VjpFrame& fr, const std::vector<Kinematics::At>& kin, VectorXd& de, VectorXd& du,
                        VectorXd& due, VectorXd* dc) const;
    void add_rotors_vjp(const VjpFrame& fr, VectorXd& de, VectorXd& du, VectorXd& due, VectorXd* dc) const;
    void add_inputs_vjp(const VjpFrame& fr, const VectorXd& fin, const VectorXd& mu, VectorXd& de, VectorXd* dc) const;
    const ScoleNonlinear* g_ = nullptr;
    std::vector<double> mass_;            // per mass point
    std::vector<Eigen::Matrix3d> J_;      // per rotor
    std::vector<double> rotor_scale_;     // per rotor: J_ = scale · Rotor::J
    MatrixXd Mconst_;                     // the e-independent part of M
    // M_ee: constant and factorised once without nonlinear points; with them, the constant part
    // in a pattern holding their local rows, factorised per e (solve_mass).
    std::shared_ptr<const Eigen::SimplicialLLT<SparseMatrix>> C_;
    SparseMatrix Cbase_;
    bool e_dependent_ = false;
    // Positions in Cbase_'s value array of each turned rotor's (a, b) column pairs and each
    // nonlinear point's local pairs, row-major over the pairs (−1: not local).
    std::vector<std::vector<int>> rotor_slots_, point_slots_;
    // The nonlinear points' maps at e, in the order of the points (empty for the others); with
    // `third`, with the third derivatives the transposed products' convective_t needs.
    std::vector<Kinematics::At> kinematics(const VectorXd& e, bool third = false) const;
    // The rigid rows of M(e): A = M_rr (6 × 6), B = M_re (6 × ne).
    void rigid_rows(const VectorXd& e, const std::vector<Kinematics::At>& kin, Eigen::Matrix<double, 6, 6>& A,
                    MatrixXd& B) const;
    VectorXd solve_mass(const VectorXd& e, const VectorXd& r) const;
    VectorXd solve_mass(const VectorXd& e, const VectorXd& r, const std::vector<Kinematics::At>& kin) const;
    VectorXd internal(const VectorXd& u, const VectorXd& e, const std::vector<Kinematics::At>& kin) const;
    // The mast's foreshortening (struct Foreshortening): its parts of the rigid rows A, B of M(e),
    // of b(u, e), and of residual_vjp (∂s/∂e into de, ∂s/∂ė into de_dot, ∂s/∂V, ∂s/∂Ω into du, and
    // ∂s/∂c into dc).
    void add_foreshortening_rows(const VectorXd& e, Eigen::Matrix<double, 6, 6>& A, MatrixXd& B) const;
    void add_foreshortening_force(const VectorXd& u, const VectorXd& e, VectorXd& b) const;
    void add_foreshortening_vjp(const VectorXd& u, const VectorXd& e, const VectorXd& a, const VectorXd& mu, VectorXd& de,
                                VectorXd& de_dot, VectorXd& du, VectorXd* dc) const;
    MatrixXd rotor_block(std::size_t j, const VectorXd& e) const;
    template <class Add>
    void for_turned_rotors(const VectorXd& e, Add&& add) const;
    // M₀⁻¹ for M₀ = [A B; Bᵀ C] (C⁻¹ by solve_C), factorised once. The solver holds a copy of
    // solve_C, whose own references (the factor of C) must outlive it: use it within the call.
    template <class SolveC>
    std::function<VectorXd(const VectorXd&)> schur_solver(const Eigen::Matrix<double, 6, 6>& A, const MatrixXd& B,
                                                          const SolveC& solve_C) const;
    // M⁻¹ r for M = M₀ + the mast's axial inertia (ΔM = Σ m g gᵀ, g = Q e), by conjugate gradients
    // preconditioned with M₀.
    VectorXd axial_inertia_solve(const VectorXd& e, const VectorXd& r,
                                 const std::function<VectorXd(const VectorXd&)>& solve0) const;
    MatrixXd K_, D_;                      // elastic blocks
    // The strain energy beyond the quadratic (struct Coupling): its coefficients.
    double k_roll_ = 0.0, k_pitch_ = 0.0, k_twist_ = 0.0;
    double coupling_energy(const VectorXd& e) const;
    void add_coupling_force(const VectorXd& e, VectorXd& out) const;                      // out += ∇W(e)
    void add_coupling_hessian(const VectorXd& e, const VectorXd& x, VectorXd& out) const;  // out += ∇²W(e) x
    // ∂/∂c of μᵀ ∇W(e), added to dc (W = W₃ + W₄).
    void add_coupling_coefficients(const VectorXd& e, const VectorXd& mu, VectorXd& dc) const;
    std::vector<double> input_scale_;     // γ_i per input (1 without a coefficient)
    double constants_ = 1.0;
  };
  Dynamics at(const VectorXd& c, double constants = 1.0) const;

  // The map G: (X, θ, e) → the linear model's DOFs (for the linearisation check).
  const MatrixXd& linear_map() const { return G_; }

private:
  void elastic_mass(Dynamics& d) const;  // at()'s elastic mass pattern, slots and factor
  // Three rows on e with few nonzero columns (a point's or a section's rows touch one element's
  // DOFs): the products the equations evaluate at every f cost O(columns), not O(ne).
  struct Rows3 {
    std::vector<int> cols;
    Eigen::Matrix<double, 3, Eigen::Dynamic> v;
    static Rows3 of(const MatrixXd& dense);
    Eigen::Vector3d times(const VectorXd& x) const;
    void add_transposed(const Eigen::Vector3d& w, VectorXd& out) const;          // out += Rowsᵀ w
    void add_left(const Eigen::Matrix3d& A, MatrixXd& out) const;                // out (3 × ne) += A Rows
  };
  // The strain energy of the mast beyond the linear model's quadratic (docs/theory.md §3.8). With the
  // section's rotation R = exp[α] exp[ψ a] (α the tilt the slopes give, ⊥ a; ψ the twist about the
  // mast's axis a) and θ = Θ e the linear rotation rows (θ_x, θ_y the slopes turned by 90°, exactly;
  // θ_z = ψ along ẑ; θ⊥ = (θ_x, θ_y, 0)), the tilt's rotation vector is α = θ⊥ asin|θ⊥|/|θ⊥| and the
  // body-frame curvature
  // κ = Zᵀ(α' − ½ α × α' + ⅙ α × (α × α')) + ψ' a is, to third order,
  //   κ⊥ = θ⊥' − ψ a × θ⊥' + ½ θ⊥ (θ⊥·θ⊥') − ½ ψ² θ⊥',   κ_a = ψ' − ½ a·(θ⊥ × θ⊥'),
  // so that ½ ∫ κᵀ C κ ds (C = diag(EI_roll, EI_pitch, GJ)) adds to the quadratic energy
  //   W₃ = ∫ [ −½ GJ θ_z' (θ_x θ_y' − θ_y θ_x') + (EI_roll − EI_pitch) θ_z θ_x' θ_y' ] ds,
  //   W₄ = ½ ∫ [ (EI_roll θ_x θ_x' + EI_pitch θ_y θ_y')(θ⊥·θ⊥') + (EI_roll − EI_pitch) θ_z² (θ_y'² − θ_x'²)
  //              + ¼ GJ (θ_x θ_y' − θ_y θ_x')² ] ds
  // (every term even in the orientation of a): the twist a bend in two planes carries, the bending
  // stiffness turning with a twisted section, and the curvature's own nonlinearity (for isotropic
  // bending ½ EI (u'·u'')², from |t'|² = |u''|² + (u'·u'')²/(1 − |u'|²)). Per Gauss point (four per
  // element: exact for the Hermite fields) the six rows (θ_x, θ_y, θ_z, θ_x', θ_y', θ_z') on the columns they touch.
  struct Coupling {
    std::vector<int> cols;
    Eigen::Matrix<double, 6, Eigen::Dynamic> rows;
    double weight = 0;
  };
  struct MassPoint {
    Eigen::Vector3d p;
    MatrixXd N;        // 3 × ne
    double weight = 0; // mass = weight · c[coefficient] (or · constants)
    int coefficient = -1;
    Rows3 n;           // N, compact
    Kinematics kin;    // active for a point nonlinear in e (N is then its linear part)
    double offset = 0; // a constant added to the mass (· constants)
  };
  // A rotor on the mast (a section) turns with the section's rotation
  // R = exp[α] exp[ψ ẑ] (struct Coupling), whose angular velocity relative to S is, to second order,
  //   ω_rel = Θ ė + p × (B ė),   p = α = P⊥ Θ e,   B = (½ P⊥ + P_z) Θ
  // (½ α × α̇ + ψ̇ α × ẑ): ω = Ω + Θ(e) ė with Θ(e) = Θ + [p]× B. The shuttle's rotor has no columns.
  // A rotor's inertia J turned by that rotation to second order, J(θ) = R J Rᵀ + O(θ³), θ = Θ e:
  // quadratic in θ, so it is held by its derivatives, J(θ) = J + Σ_k θ_k (J_k + ½ Σ_l θ_l J_kl)
  // (docs/theory.md §3.8). Linear in J.
  struct Turning {
    std::array<Eigen::Matrix3d, 3> first;                  // J_k = ∂J/∂θ_k at θ = 0
    std::array<std::array<Eigen::Matrix3d, 3>, 3> second;  // J_kl = ∂²J/∂θ_k∂θ_l
    Turning() = default;
    explicit Turning(const Eigen::Matrix3d& J);
    Eigen::Matrix3d change(const Eigen::Vector3d& theta) const;  // J(θ) − J
    // ∂J/∂θ_k at θ, k = 0, 1, 2
    std::array<Eigen::Matrix3d, 3> slopes(const Eigen::Vector3d& theta) const;
    // ∇_θ (u · ∇_θ (a · J(θ) b)) (constant in θ)
    Eigen::Vector3d curvature(const Eigen::Vector3d& u, const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;
  };
  struct Rotor {
    Eigen::Matrix3d J;
    MatrixXd Theta;    // 3 × ne
    int coefficient = -1;
    Rows3 th;          // Θ, compact
    Eigen::Matrix<double, 3, Eigen::Dynamic> half;  // B on th.cols
    Turning turn;      // of J (unscaled)
    Eigen::Vector3d tilt(const VectorXd& x) const;  // P⊥ Θ x
    Eigen::Matrix<double, 3, Eigen::Dynamic> jacobian(const VectorXd& e) const;  // Θ(e) on th.cols
  };
  struct Input {
    VectorXd q0;         // Gᵀ b at e = 0 (speeds())
    bool arm = false;    // a force at a point: Q_Ω += (N e) × d f
    MatrixXd N;
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    int coefficient = -1;
    // At a point nonlinear in e (the reflector's CM): also Q_Ω += (r(e) − p − N e) × d f and
    // Q_e += (N(e) − N)ᵀ d f, the generalized force L(e)ᵀ d f of the point's own kinematics.
    const Kinematics* kin = nullptr;
  };
  struct Sensor {
    enum class Kind { ShuttleRotation, ShuttleDisplacement, ShuttleVelocity, ShuttleAcceleration, Row, RateRow,
                      PointAcceleration };
    Kind kind = Kind::Row;
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    Eigen::RowVectorXd row;  // on e or ė
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    MatrixXd N;
    const Kinematics* kin = nullptr;  // an accelerometer at a point nonlinear in e (the reflector's CM)
  };

  // The mast's foreshortening (docs/theory.md §3.8, "The mast's foreshortening"). An inextensible
  // mast point at s moves back towards the root by w(s) = ½ eᵀ Q(s) e, Q(s) = ∫₀ˢ Θ⊥ᵀ Θ⊥ ds' (Θ⊥ the
  // slopes' rows, the tilt's θ_x, θ_y). The mast's mass points carry it through the kinetic energy
  //   T_fs = Σ_i m_i [k_i · (t ẇ_i + (Ω × t) w_i) + ½ ẇ_i²],   k_i = V + Ω × r_i + N_i ė,
  // (t the unit vector to the root): the cross term of the point's velocity without the shift with
  // the velocity of the shift, and the shift's own axial inertia; ½ m w² |Ω × t|² is left out: like
  // ½ m ẇ² of fourth order in the energy, but smaller by (Ω / ω)² (ω the mast's frequencies, Ω
  // the slew rate); it would add m w² (I − t tᵀ) to M_ΩΩ, a centrifugal −m w |Ω × t|² Q e to the
  // e row and terms to the Ω row. As t·N_i = 0 the cross term adds only to
  // the rigid rows of M (A, B) and to b; its e-row force includes Σ_i m_i (Q_i e) t·K_i, K_i the
  // point's inertial acceleration: the P-delta stiffness of the axial inertial load. The axial
  // inertia adds Σ_i m_i g_i g_iᵀ (g_i = Q_i e) to M_ee and Σ_i m_i g_i ėᵀ Q_i ė to b. Held as the
  // slopes' rows at three Gauss points per element (|Θ⊥ e|² has degree 4 there) and, per mast
  // point, at three on the part of its own element below it, so that  xᵀ Q_i y = Σ_{elements below}
  // Σ_q ω_q (R_q x)·(R_q y) + the partial element's sum,  and Σ_i γ_i Q_i x takes suffix sums over
  // the elements: O(ne) for all points (the dense Σ m g gᵀ x too).
  struct Foreshortening {
    struct Node {
      std::vector<int> cols;
      Eigen::Matrix<double, 2, Eigen::Dynamic> rows;  // Θ⊥ on cols
      double weight = 0.0;
    };
    // Θ⊥ x at every node: the elements' (3 per element) first, then the points' partial ones (3 each).
    using Slopes = Eigen::Matrix<double, 2, Eigen::Dynamic>;
    std::vector<Node> node;
    int elements = 0;
    std::vector<int> element_of;     // per mast point (ascending)
    std::vector<std::size_t> point;  // per mast point: its index in points_
    Eigen::Vector3d t = Eigen::Vector3d::UnitZ();
    std::size_t size() const { return point.size(); }
    Slopes slopes(const VectorXd& x) const;
    void forms(const Slopes& X, const Slopes& Y, std::vector<double>& out) const;       // out_i = xᵀ Q_i y
    void apply(const std::vector<double>& gamma, const Slopes& X, VectorXd& out) const;  // out += Σ γ_i Q_i x
    // out (6 × ne) += Σ_i γ_i (Q_i x)ᵀ
    void apply_rows(const std::vector<Eigen::Matrix<double, 6, 1>>& gamma, const Slopes& X, MatrixXd& out) const;
    void add(std::size_t j, const Eigen::Vector2d& a, VectorXd& out) const;  // out += node j's Rᵀ a
    // visit(node, c) for every node with its coefficient in Σ_i γ_i Q_i: γ_i for point i's own
    // nodes, Σ_{points above} γ_i for an element's (suffix sums from the mast's end).
    template <class G, class Visit>
    void coefficients(const std::vector<G>& gamma, G zero, Visit&& visit) const;
  };

  // The constructor's parts, in order (scole_nonlinear/assembly.cpp).
  MatrixXd on_e(const MatrixXd& rows) const;  // rows restricted to the elastic DOFs e
  void add_mast(const ScoleFE& fe);
  void add_foreshortening(const ScoleFE& fe);
  void add_reflector(const ScoleFE& fe);
  void add_shuttle_and_proof_masses(const ScoleFE& fe);
  void index_points();
  const Kinematics* reflector_kinematics(const ScoleFE& fe) const;
  void add_inputs(const ScoleFE& fe, const std::vector<io::InputSpec>& inputs);
  void add_sensors(const ScoleFE& fe, const std::vector<io::SensorSpec>& sensors);

  int ne_ = 0, ncoef_ = 0;
  Foreshortening fs_;
  std::vector<MassPoint> points_;
  std::vector<std::size_t> axial_rep_;  // per axial group (Kinematics::axial_group): its first point
  std::vector<Rotor> rotors_;
  std::vector<Coupling> coupling_;
  std::vector<OperatorTerm> stiffness_, damping_;  // e-blocks
  std::vector<Input> inputs_;
  std::vector<Sensor> sensors_;
  std::vector<std::string> sensor_names_;
  MatrixXd G_;
};

// The nonlinear SCOLE model of a scenario on `elements` elements (a SCOLE scenario: its mast is
// uniform, identification.sections 0 or 1; std::logic_error for another structure, which
// io::validate_scenario refuses with identification.model: nonlinear).
ScoleNonlinear scole_nonlinear(const io::Scenario& scenario, int elements);

}  // namespace scoleid::identify
