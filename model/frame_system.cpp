#include "scoleid/model/frame_system.h"

#include <algorithm>
#include <cmath>

#include "scoleid/model/hencky.h"
#include "scoleid/model/joint_forces.h"

namespace scoleid::model {

using namespace SimTK;

FrameSystem::FrameSystem(const io::FrameSpec& frame, int segments) {
  const int n = frame.storeys();
  length_ = frame.height();
  root_R_ = Vec3(0);
  axis_B_ = axis_R_ = Vec3(1, 0, 0);
  base_.push_back(0.0);
  for (int k = 0; k < n; ++k) {
    const double hk = frame.heights[static_cast<std::size_t>(k)];
    base_.push_back(base_.back() + hk);
    storey_segments_.push_back(std::max(2, static_cast<int>(std::lround(segments * hk / length_))));
  }
  std::vector<JointSpring> joints;
  std::vector<AnchorSpring> anchors;
  std::vector<RelativeSpring> heads;
  const double span = (frame.columns - 1) * frame.bay;
  MobilizedBody below = matter_.Ground();  // the floor under the storey
  for (int k = 0; k < n; ++k) {
    const double hk = frame.heights[static_cast<std::size_t>(k)];
    const double EI = frame.EI[static_cast<std::size_t>(k)];
    const int m = storey_segments_[static_cast<std::size_t>(k)];
    const HenckyLumping lump = hencky_lumping(m, PiecewiseField{hk, {EI}}, PiecewiseField{hk, {frame.tau * EI}});
    const double h = lump.h;
    const double bar_mass = frame.rho_A * h, J = bar_mass * h * h / 12.0;
    const MassProperties bar(bar_mass, Vec3(h / 2, 0, 0), Inertia(Vec3(0, J, J)).shiftFromMassCenter(Vec3(-h / 2, 0, 0), bar_mass));
    // The bars' square-root damping: D = ∫ 2ζ√(ρA EI) ds over the bar (docs/theory.md §2.6, §9.2).
    const double D = 2.0 * frame.zeta * std::sqrt(frame.rho_A * EI) * h;
    // The foot of column c on the floor below: on the ground at height base_[k]; on a floor block
    // (its frame at the first column's head) at its column point.
    const auto foot = [&](int c) { return Transform(Vec3(k == 0 ? base_[0] : 0.0, c * frame.bay, 0)); };
    std::vector<MobilizedBody> head_bars;
    for (int c = 0; c < frame.columns; ++c) {
      MobilizedBody parent = below;
      for (int i = 0; i < m; ++i) {
        Body::Rigid body(bar);
        body.addDecoration(Transform(Rotation(-Pi / 2, ZAxis), Vec3(h / 2, 0, 0)),
                           DecorativeCylinder(0.01 * length_, h / 2).setColor(Vec3(0.6, 0.6, 0.7)));
        const MobilizedBody::Pin seg(parent, i == 0 ? foot(c) : Transform(Vec3(h, 0, 0)), body, Transform());
        // Joint 0 is the clamped foot (2EI/h), the others interior (EI/h).
        joints.push_back({seg.getMobilizedBodyIndex(), 0, lump.stiffness[static_cast<std::size_t>(i)],
                          lump.damping[static_cast<std::size_t>(i)]});
        if (D > 0.0) anchors.push_back({seg.getMobilizedBodyIndex(), 0.0, D});
        if (c == 0) segment_bodies_.push_back(seg.getMobilizedBodyIndex());
        parent = seg;
      }
      head_bars.push_back(parent);
    }
    // The floor block on the first column's head, its clamped-end spring the Pin's.
    const double mk = frame.floor_mass[static_cast<std::size_t>(k)];
    const double width = frame.columns * frame.bay, thick = 0.1 * frame.bay;
    const Inertia block = Inertia(Vec3(mk * thick * thick / 12, mk * width * width / 12,
                                       mk * (width * width + thick * thick) / 12));
    const Vec3 com(0, span / 2, 0);
    Body::Rigid floor_body(MassProperties(mk, com, block.shiftFromMassCenter(-com, mk)));
    floor_body.addDecoration(Transform(com), DecorativeBrick(Vec3(thick / 2, width / 2, thick / 2)).setColor(Vec3(0.5, 0.5, 0.5)));
    MobilizedBody::Pin floor(head_bars[0], Transform(Vec3(h, 0, 0)), floor_body, Transform());
    joints.push_back({floor.getMobilizedBodyIndex(), 0, lump.stiffness[static_cast<std::size_t>(m)],
                      lump.damping[static_cast<std::size_t>(m)]});
    // Every other column's head closed onto the floor: its end point on the floor's column point,
    // and the clamped-end spring between the two bodies.
    // (The vertical tie of the third and further columns is left out: at the straight frame their
    // rows are proportional to the second column's — a floor's turn is the one thing they hold —
    // and a rank-deficient constraint Jacobian is left to no projection. To first order in the
    // sway nothing moves along them.)
    for (int c = 1; c < frame.columns; ++c) {
      if (c == 1) Constraint::PointInPlane(floor, UnitVec3(1, 0, 0), 0.0, head_bars[static_cast<std::size_t>(c)], Vec3(h, 0, 0));
      Constraint::PointInPlane(floor, UnitVec3(0, 1, 0), c * frame.bay, head_bars[static_cast<std::size_t>(c)], Vec3(h, 0, 0));
      heads.push_back({head_bars[static_cast<std::size_t>(c)].getMobilizedBodyIndex(), floor.getMobilizedBodyIndex(),
                       lump.stiffness[static_cast<std::size_t>(m)], lump.damping[static_cast<std::size_t>(m)]});
    }
    floors_.push_back(floor.getMobilizedBodyIndex());
    below = floor;
  }
  joint_springs_ = joints;
  Force::Custom(forces_, new JointForces(matter_, std::move(joints), std::move(anchors), {}, {}, std::move(heads)));
}

Station FrameSystem::station_at(double s) const {
  const int n = static_cast<int>(storey_segments_.size());
  int k = 0;
  while (k + 1 < n && s > base_[static_cast<std::size_t>(k + 1)]) ++k;
  int first = 0;
  for (int j = 0; j < k; ++j) first += storey_segments_[static_cast<std::size_t>(j)];
  const int m = storey_segments_[static_cast<std::size_t>(k)];
  const double h = (base_[static_cast<std::size_t>(k + 1)] - base_[static_cast<std::size_t>(k)]) / m;
  const double x = std::clamp(s - base_[static_cast<std::size_t>(k)], 0.0, m * h);
  const int i = std::min(m - 1, static_cast<int>(std::floor(x / h)));
  Station st;
  st.body = segment_bodies_[static_cast<std::size_t>(first + i)];
  st.p_BS = Vec3(x - i * h, 0, 0);
  st.p_RS0 = Vec3(s, 0, 0);
  return st;
}

double FrameSystem::centre_coordinate(double s) const {
  // Segment centres in order up the first column; linear between neighbours.
  const int n = static_cast<int>(storey_segments_.size());
  int first = 0;
  double prev_c = -1, prev_s = 0;
  for (int k = 0; k < n; ++k) {
    const int m = storey_segments_[static_cast<std::size_t>(k)];
    const double h = (base_[static_cast<std::size_t>(k + 1)] - base_[static_cast<std::size_t>(k)]) / m;
    for (int i = 0; i < m; ++i) {
      const double sc = base_[static_cast<std::size_t>(k)] + (i + 0.5) * h;
      const int idx = first + i;
      if (s < sc) return idx == 0 ? s / h - 0.5 : prev_c + (s - prev_s) / (sc - prev_s);
      prev_c = idx;
      prev_s = sc;
    }
    first += m;
  }
  return prev_c + 1.0;  // beyond the last centre
}

// Its storeys' bars differ in length: no arc range.
std::string FrameSystem::segment_name(int i) const {
  return "frame's first column, segment " + std::to_string(i + 1) + " of " + std::to_string(segments());
}

std::unique_ptr<Structure> make_frame_system(const io::Scenario& sc, int segments) {
  return std::make_unique<FrameSystem>(sc.frame, segments);
}

}  // namespace scoleid::model
