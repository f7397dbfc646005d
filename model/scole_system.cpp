#include "scoleid/model/scole_system.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "scoleid/io/error.h"
#include "scoleid/model/joint_forces.h"

namespace scoleid::model {

using namespace SimTK;

namespace {
Inertia inertia_of(const io::RigidBodySpec& b) {
  return Inertia(Vec3(b.Ixx, b.Iyy, b.Izz), Vec3(b.Ixy, b.Ixz, b.Iyz));
}
}  // namespace

// The builders, body by body in the order the tree is built (shuttle, mast segments, reflector,
// actuators: the mobilized bodies' indices follow it), with the joints' springs and the segments'
// dampers collected on the way.
struct ScoleSystem::Build {
  ScoleSystem& sys;
  const io::ScoleSpec& sc;
  int n;
  HenckyLumping roll, pitch, torsion;  // per joint: the segments' and the free end's half cell
  std::vector<JointSpring> joints;
  std::vector<RelativeDamper> dampers;

  Build(ScoleSystem& system, const io::ScoleSpec& spec, int segments) : sys(system), sc(spec), n(segments) {
    const double L = sc.length;
    auto uniform = [L](double v) { return PiecewiseField{L, {v}}; };
    // Bending is damped per segment relative to the shuttle (square-root damping), not at the
    // joints; torsion at the joints (Kelvin–Voigt, c_psi = 2 zeta sqrt(rho_I_psi GJ) 2L/pi).
    roll = hencky_lumping(n, uniform(sc.EI_roll), uniform(0.0));
    pitch = hencky_lumping(n, uniform(sc.EI_pitch), uniform(0.0));
    torsion = hencky_lumping(n, uniform(sc.GJ), uniform(4.0 * L / Pi * sc.zeta * std::sqrt(sc.rho_I_psi * sc.GJ)));
  }
  void add_joint(MobilizedBodyIndex b, std::size_t j) {
    joints.push_back({b, 0, roll.stiffness[j], roll.damping[j]});
    joints.push_back({b, 1, pitch.stiffness[j], pitch.damping[j]});
    joints.push_back({b, 2, torsion.stiffness[j], torsion.damping[j]});
  }

  // Decorations are for the visualizer only: shuttle-sized box, mast tube, reflector dish.
  MobilizedBody shuttle() {
    Body::Rigid body(MassProperties(sc.shuttle.mass, Vec3(0), inertia_of(sc.shuttle)));
    body.addDecoration(Transform(), DecorativeBrick(Vec3(60, 12, 10)).setColor(Vec3(0.9, 0.9, 0.9)));
    MobilizedBody::Free shuttle(sys.matter_.Ground(), Transform(), body, Transform());
    sys.shuttle_ = shuttle.getMobilizedBodyIndex();
    return shuttle;
  }

  // n rigid segments on Gimbals from the mast root; returns the last.
  MobilizedBody mast(MobilizedBody shuttle) {
    const double h = roll.h;
    const Vec3 slope_damping(2 * sc.zeta * std::sqrt(sc.rho_A * sc.EI_roll) * h,
                             2 * sc.zeta * std::sqrt(sc.rho_A * sc.EI_pitch) * h, 0.0);
    const double m = sc.rho_A * h;
    const double Ib = m * h * h / 12.0 + 0.5 * sc.rho_I_psi * h;
    const double Ip = sc.rho_I_psi * h;
    const Vec3 com(0, 0, -h / 2);
    Body::Rigid segment_body(MassProperties(m, com, Inertia(Vec3(Ib, Ib, Ip)).shiftFromMassCenter(-com, m)));
    segment_body.addDecoration(Transform(Rotation(Pi / 2, XAxis), com),
                               DecorativeCylinder(1.0, h / 2).setColor(Vec3(0.8, 0.6, 0.2)));
    MobilizedBody parent = shuttle;
    for (int i = 0; i < n; ++i) {
      const Transform X_PF = i == 0 ? Transform(sys.root_R_) : Transform(Vec3(0, 0, -h));
      MobilizedBody::Gimbal seg(parent, X_PF, segment_body, Transform());
      add_joint(seg.getMobilizedBodyIndex(), static_cast<std::size_t>(i));
      if (sc.zeta > 0.0) dampers.push_back({seg.getMobilizedBodyIndex(), sys.shuttle_, slope_damping});
      sys.segment_bodies_.push_back(seg.getMobilizedBodyIndex());
      parent = seg;
    }
    return parent;
  }

  // The reflector hangs on a Gimbal at s = L carrying the free end's half-cell springs (2EI/h,
  // 2GJ/h): the last segment's rotation is the mast's at L - h/2, and only the end cell's
  // compliance carries it to L. Welding the reflector to the last segment instead leaves an
  // O(h) error in the tip rotation, which the reflector's inertia turns into O(1/n) frequencies.
  void reflector(MobilizedBody last_segment) {
    const Vec3 r(sc.reflector_rx, sc.reflector_ry, 0.0);
    const double mr = sc.reflector.mass;
    Body::Rigid body(MassProperties(mr, r, inertia_of(sc.reflector).shiftFromMassCenter(-r, mr)));
    body.addDecoration(Transform(Rotation(Pi / 2, XAxis), r),
                       DecorativeCylinder(30.0, 0.5).setColor(Vec3(0.3, 0.5, 0.9)));
    MobilizedBody::Gimbal reflector(last_segment, Transform(Vec3(0, 0, -roll.h)), body, Transform());
    add_joint(reflector.getMobilizedBodyIndex(), static_cast<std::size_t>(n));
    sys.reflector_ = sys.tip_body_ = reflector.getMobilizedBodyIndex();
    sys.reflector_station_ = {sys.reflector_, r, sys.root_R_ + sys.axis_R_ * sc.length + r};
  }

  // Carriage: massless, on a Slider along the segment x axis; proof mass on a Slider along y
  // (the Slider moves along its frames' x axis, so the second pair of frames is turned 90° about z).
  void actuators() {
    const Rotation x_to_y(Pi / 2, ZAxis);
    for (double s : sc.actuator_locations) {
      const Station st = sys.station_at(s);
      MobilizedBody::Slider carriage(sys.matter_.updMobilizedBody(st.body), Transform(st.p_BS), Body::Massless(),
                                     Transform());
      MobilizedBody::Slider proof(carriage, Transform(x_to_y),
                                  Body::Rigid(MassProperties(sc.actuator_mass, Vec3(0), Inertia(0))),
                                  Transform(x_to_y));
      sys.sliders_.push_back(carriage.getMobilizedBodyIndex());
      sys.sliders_.push_back(proof.getMobilizedBodyIndex());
      // Centering spring and damper on each slider (docs/theory.md §3.7).
      if (sc.actuator_stiffness > 0.0 || sc.actuator_damping > 0.0)
        for (MobilizedBodyIndex b : {carriage.getMobilizedBodyIndex(), proof.getMobilizedBodyIndex()})
          joints.push_back({b, 0, sc.actuator_stiffness, sc.actuator_damping});
    }
  }
};

ScoleSystem::ScoleSystem(const io::ScoleSpec& sc, int n) {
  length_ = sc.length;
  actuator_lag_ = sc.actuator_lag;
  actuator_stroke_ = sc.actuator_stroke;
  root_R_ = Vec3(sc.mast_root[0], sc.mast_root[1], sc.mast_root[2]);
  axis_B_ = axis_R_ = Vec3(0, 0, -1);
  if (!sc.bending_rotary_inertia)
    throw std::invalid_argument(
        "ScoleSystem: a chain of rigid segments always carries the section's bending rotary inertia");
  Build b(*this, sc, n);
  b.reflector(b.mast(b.shuttle()));
  b.actuators();
  joint_springs_ = b.joints;
  Force::Custom(forces_, new JointForces(matter_, std::move(b.joints), {}, std::move(b.dampers)));
}

Station ScoleSystem::named_station(io::Site at) const {
  if (at == io::Site::Shuttle) return {shuttle_, Vec3(0), Vec3(0)};
  if (at == io::Site::Reflector) return reflector_station_;
  return {};
}

MobilizedBodyIndex ScoleSystem::actuator_slider(int k, int axis) const {
  const std::size_t i = static_cast<std::size_t>(2 * (k - 1) + axis);
  return k >= 1 && i < sliders_.size() ? sliders_[i] : MobilizedBodyIndex();
}

std::unique_ptr<Structure> make_scole_system(const io::Scenario& sc, int segments) {
  if (!sc.scole.bending_rotary_inertia)
    io::fail_field(sc.source, "scole.bending_rotary_inertia",
                   "must be true for the Simbody truth: its rigid segments carry the section's bending rotary "
                   "inertia (a body with polar inertia J has Ixx + Iyy >= J); drop it on the identifier's side only",
                   "false");
  return std::make_unique<ScoleSystem>(sc.scole, segments);
}

}  // namespace scoleid::model
