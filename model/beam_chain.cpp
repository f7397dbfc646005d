#include "scoleid/model/beam_chain.h"

#include <algorithm>
#include <cmath>

#include "scoleid/model/joint_forces.h"

namespace scoleid::model {

using namespace SimTK;

BeamChain::BeamChain(const io::BeamSpec& beam, int n) {
  length_ = beam.length;
  root_R_ = Vec3(0);
  axis_B_ = axis_R_ = Vec3(1, 0, 0);

  // Kelvin–Voigt: c_kv (one value) lumps into the joint dampers the way EI lumps into the joint
  // springs (hencky.h, docs/theory.md §9.1).
  PiecewiseField EI{beam.length, beam.EI};
  PiecewiseField c{beam.length, {beam.c_kv}};
  lumping_ = hencky_lumping(n, EI, c);
  const double h = lumping_.h;
  // Chen–Russell: bar i on [i h, (i+1) h] dissipates 1/2 D_i omega_i^2, D_i = integral of
  // d(s) = 2 zeta sqrt(rho_A EI(s)) over the bar (docs/theory.md §9.2).
  const auto chen_russell = [&](double a, double b) {
    const int m = static_cast<int>(beam.EI.size());
    const double w = beam.length / m;
    double sum = 0.0;
    for (int k = 0; k < m; ++k) {
      const double lo = std::max(a, k * w), hi = std::min(b, (k + 1) * w);
      if (hi > lo) sum += (hi - lo) * 2.0 * beam.zeta * std::sqrt(beam.rho_A * beam.EI[static_cast<std::size_t>(k)]);
    }
    return sum;
  };

  // Thin rigid bar along its x axis: no inertia about its own axis.
  const double m = beam.rho_A * h;
  const double J = m * h * h / 12.0;
  const MassProperties bar(m, Vec3(h / 2, 0, 0), Inertia(Vec3(0, J, J)).shiftFromMassCenter(Vec3(-h / 2, 0, 0), m));

  std::vector<JointSpring> joints;
  std::vector<AnchorSpring> anchors;
  MobilizedBody parent = matter_.Ground();
  // A tip mass without rotary inertia rides on the last bar's end; with rotary inertia it is a
  // body of its own on a Pin at s = L with the end-cell spring (2EI/h): the last bar's slope is
  // w_s at L - h/2, and only the end cell's compliance carries it to L (O(h^2), not O(h)).
  const bool tip_body = beam.tip_inertia > 0.0;
  for (int i = 0; i < n; ++i) {
    MassProperties mp = bar;
    if (i == n - 1 && beam.tip_mass > 0.0 && !tip_body) {
      const double M = m + beam.tip_mass;
      const Vec3 com = (m * Vec3(h / 2, 0, 0) + beam.tip_mass * Vec3(h, 0, 0)) / M;
      mp = MassProperties(M, com, bar.getInertia() + Inertia(Vec3(h, 0, 0), beam.tip_mass));
    }
    Body::Rigid body(mp);
    // Geometry for the visualizer only (a cylinder's axis is its y).
    body.addDecoration(Transform(Rotation(-Pi / 2, ZAxis), Vec3(h / 2, 0, 0)),
                       DecorativeCylinder(0.02 * length_, h / 2).setColor(Vec3(0.6, 0.6, 0.7)));
    const Transform X_PF = i == 0 ? Transform() : Transform(Vec3(h, 0, 0));
    MobilizedBody seg;
    if (i == 0 && beam.left == io::EndCondition::Free) {
      seg = MobilizedBody::Planar(parent, X_PF, body, Transform());
    } else {
      seg = MobilizedBody::Pin(parent, X_PF, body, Transform());
    }
    const auto j = static_cast<std::size_t>(i);
    if (i > 0) joints.push_back({seg.getMobilizedBodyIndex(), 0, lumping_.stiffness[j], lumping_.damping[j]});
    if (i == 0 && beam.left == io::EndCondition::Clamped)
      joints.push_back({seg.getMobilizedBodyIndex(), 0, lumping_.stiffness[0], lumping_.damping[0]});
    if (beam.zeta > 0.0) anchors.push_back({seg.getMobilizedBodyIndex(), 0.0, chen_russell(i * h, (i + 1) * h)});
    segment_bodies_.push_back(seg.getMobilizedBodyIndex());
    parent = seg;
  }
  if (tip_body) {
    const MobilizedBody::Pin tip(parent, Transform(Vec3(h, 0, 0)),
                                 Body::Rigid(MassProperties(beam.tip_mass, Vec3(0),
                                                            Inertia(Vec3(0, beam.tip_inertia, beam.tip_inertia)))),
                                 Transform());
    const auto j = static_cast<std::size_t>(n);
    joints.push_back({tip.getMobilizedBodyIndex(), 0, lumping_.stiffness[j], lumping_.damping[j]});
    tip_body_ = tip.getMobilizedBodyIndex();
  }
  if (beam.right != io::EndCondition::Free) {
    Constraint::PointInPlane(matter_.updGround(), UnitVec3(0, 1, 0), 0.0, parent, Vec3(h, 0, 0));
    if (beam.right == io::EndCondition::Clamped) {
      const auto j = static_cast<std::size_t>(n);
      anchors.push_back({parent.getMobilizedBodyIndex(), lumping_.stiffness[j], lumping_.damping[j]});
    }
  }
  joint_springs_ = joints;
  Force::Custom(forces_, new JointForces(matter_, std::move(joints), std::move(anchors)));
}

}  // namespace scoleid::model
