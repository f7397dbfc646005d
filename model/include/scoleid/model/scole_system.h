#pragma once
// The SCOLE multibody (docs/theory.md §3, §9), slug-ft-s.
//
// Shuttle: rigid body on a Free mobilizer, no gravity (orbit); body frame S at its CM, x roll,
// y pitch, z yaw. Mast: n rigid segments of length h = L/n leaving the shuttle at mast_root
// along S -z, each a Gimbal (body-fixed x-y-z rotations, u = qdot) from the previous segment's
// tip (the first from the shuttle). Each segment carries mass rho_A h at its centre, bending
// rotary inertia rho_A h^3/12 + rho_I_psi h/2 about x and y (the cross-section's own rotary
// inertia — a rigid body must satisfy Ixx + Iyy >= Izz) and polar inertia rho_I_psi h.
// Joint springs/dampers (hencky.h): rotation about x (roll bending, displacement along y) with
// EI_roll, about y (pitch bending, displacement along x) with EI_pitch, about z (torsion) with
// GJ; the root joint is clamped to the shuttle (2EI/h, 2GJ/h), the tip is free. Dampers are the
// Kelvin–Voigt terms, c = 2 zeta sqrt(rho_A EI) and 2 zeta sqrt(rho_I_psi GJ).
// Reflector: rigid body with its CM at (r_x, r_y, 0) from the mast tip and its inertia about its
// CM in axes parallel to S (undeformed), on a Gimbal at the tip carrying the free end's half-cell
// springs (2EI/h, 2GJ/h) — the Hencky end treatment that keeps the tip rotation O(h^2).
// Proof-mass actuators at s2, s3: a massless carriage on a Slider along the segment's x, and
// the proof mass on a Slider along y on the carriage; a commanded slider force acts on the
// proof mass and reacts on the mast (internal forces: total momentum is conserved).
// The mast rotations are geometrically exact (large shuttle motion couples with the mast
// nonlinearly); the spring law is linear in the Gimbal angles, as the PDE is in the slopes.
#include "scoleid/io/scenario.h"
#include "scoleid/model/structure.h"

namespace scoleid::model {

class ScoleSystem : public Structure {
public:
  ScoleSystem(const io::ScoleSpec& scole, int segments);
  io::Structure kind() const override { return io::Structure::Scole; }
  bool planar() const override { return false; }
  double actuator_lag() const override { return actuator_lag_; }
  SimTK::MobilizedBodyIndex reference_body() const override { return shuttle_; }
  Station named_station(io::Site at) const override;
  Station site_station(io::Site at, double location) const override {
    return at == io::Site::Mast ? station_at(location) : named_station(at);
  }
  bool chain_site(io::Site at) const override { return at == io::Site::Mast; }
  SimTK::MobilizedBodyIndex actuator_slider(int k, int axis) const override;
  int actuator_count() const override { return static_cast<int>(sliders_.size() / 2); }
  double actuator_stroke() const override { return actuator_stroke_; }
  std::string chain_name() const override { return "mast"; }
  std::string tip_name() const override { return "reflector"; }
  std::string reference_name() const override { return "shuttle"; }

  SimTK::MobilizedBodyIndex shuttle() const { return shuttle_; }
  SimTK::MobilizedBodyIndex reflector() const { return reflector_; }

private:
 struct Build;  // the per-body builders (scole_system.cpp)
 SimTK::MobilizedBodyIndex shuttle_, reflector_;
 Station reflector_station_;
 std::vector<SimTK::MobilizedBodyIndex> sliders_;  // [2 (k-1) + axis]
 double actuator_lag_ = 0.0;
 double actuator_stroke_ = 0.0;
};

// The truth's SCOLE (truth_run.cpp's registry row); InputError for what the chain cannot build.
std::unique_ptr<Structure> make_scole_system(const io::Scenario& sc, int segments);

}  // namespace scoleid::model
