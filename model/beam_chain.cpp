#include "scoleid/model/beam_chain.h"

#include <algorithm>
#include <cmath>

#include "scoleid/model/joint_forces.h"
#include "scoleid/model/sensors.h"

namespace scoleid::model {

using namespace SimTK;

double end_rotational_spring(const io::BeamSpec& beam, int end) {
  double k = 0.0;
  for (const auto* group : {&beam.supports, &beam.attachments})
    for (const auto& e : *group)
      if (e.location == (end == 0 ? 0.0 : beam.length)) k += e.k_theta;
  return k;
}

double end_series_stiffness(const io::BeamSpec& beam, int end, double k0) {
  const double k = end_rotational_spring(beam, end);
  return k > 0.0 ? k * k0 / (k + k0) : 0.0;
}

BeamChain::BeamChain(const io::BeamSpec& beam, int n) : beam_(beam) {
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
  std::vector<PointSpring> points;
  // Point elements (supports, attachments; docs/theory.md §2.5, §9.1): each rides on the bar that
  // holds its station (bar i on [i h, (i+1) h], s = L on the last bar).
  std::vector<io::PointElement> elements = beam.supports;
  elements.insert(elements.end(), beam.attachments.begin(), beam.attachments.end());
  const auto bar_of = [&](double s, double& x) {
    const int i = std::min(n - 1, std::max(0, static_cast<int>(std::floor(s / h))));
    x = s - i * h;
    return i;
  };
  // An end's rotational spring-dashpot in series with the end cell's joint spring k0 (and damper
  // c0): the two springs carry one moment, k = kθ k0 / (kθ + k0); the dashpots take the rotation
  // the springs share out, c = cθ (k/kθ)² + c0 (k/k0)² (exact as the cell's mass → 0).
  double k_theta_end[2] = {0.0, 0.0}, c_theta_end[2] = {0.0, 0.0};
  std::vector<std::pair<int, io::PointElement>> interior_rotation;
  for (const auto& e : elements) {
    double x = 0.0;
    const int i = bar_of(e.location, x);
    if (e.k_w > 0.0 || e.c_w > 0.0) points.push_back({MobilizedBodyIndex(), Vec3(x, 0, 0), e.k_w, e.c_w, MobilizedBodyIndex(), Vec3(0.0)});
    if (e.k_theta > 0.0 || e.c_theta > 0.0) {
      const int end = e.location == 0.0 ? 0 : e.location == length_ ? 1 : -1;
      if (end >= 0 && e.k_theta > 0.0) {
        k_theta_end[end] += e.k_theta;
        c_theta_end[end] += e.c_theta;
      } else {
        interior_rotation.push_back({i, e});  // an anchor on its bar (O(h): the bar's angle is the mean slope)
      }
    }
  }
  std::vector<int> point_bar;
  for (const auto& e : elements) {
    double x = 0.0;
    if (e.k_w > 0.0 || e.c_w > 0.0) point_bar.push_back(bar_of(e.location, x));
  }
  const auto series = [](double kt, double ct, double k0, double c0, double& k, double& c) {
    k = kt * k0 / (kt + k0);
    c = ct * (k / kt) * (k / kt) + c0 * (k / k0) * (k / k0);
  };
  MobilizedBody parent = matter_.Ground();
  // A tip mass without rotary inertia rides on the last bar's end; with rotary inertia it is a
  // body of its own on a Pin at s = L with the end-cell spring (2EI/h): the last bar's slope is
  // w_s at L - h/2, and only the end cell's compliance carries it to L (O(h^2), not O(h)).
  const bool tip_body = beam.tip_inertia > 0.0;
  for (int i = 0; i < n; ++i) {
    // The bar, a tip mass without rotary inertia at its end, and the point elements' masses at
    // their stations with their rotary inertias (about the origin: the point's share plus J).
    double M = m;
    Vec3 moment = m * Vec3(h / 2, 0, 0);
    Inertia inertia = bar.getInertia();
    bool added = false;
    const auto add_point = [&](double mass, double J, double x) {
      added = true;
      M += mass;
      moment += mass * Vec3(x, 0, 0);
      inertia += Inertia(Vec3(x, 0, 0), mass) + Inertia(Vec3(0, J, J));
    };
    if (i == n - 1 && beam.tip_mass > 0.0 && !tip_body) add_point(beam.tip_mass, 0.0, h);
    for (const auto& e : elements) {
      double x = 0.0;
      // At s = L with a tip body, a rotary inertia rides the tip body (its angle is the end slope).
      const double J = tip_body && e.location == length_ ? 0.0 : e.inertia;
      if ((e.mass > 0.0 || J > 0.0) && bar_of(e.location, x) == i) add_point(e.mass, J, x);
    }
    const MassProperties mp = added ? MassProperties(M, moment / M, inertia) : bar;
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
    if (i == 0 && k_theta_end[0] > 0.0) {
      double k = 0.0, c = 0.0;
      series(k_theta_end[0], c_theta_end[0], lumping_.stiffness[0], lumping_.damping[0], k, c);
      if (beam.left == io::EndCondition::Pinned) joints.push_back({seg.getMobilizedBodyIndex(), 0, k, c});
      else anchors.push_back({seg.getMobilizedBodyIndex(), k, c});  // free: the Planar body's angle
    }
    if (beam.zeta > 0.0) anchors.push_back({seg.getMobilizedBodyIndex(), 0.0, chen_russell(i * h, (i + 1) * h)});
    segment_bodies_.push_back(seg.getMobilizedBodyIndex());
    parent = seg;
  }
  if (tip_body) {
    double J = beam.tip_inertia;
    for (const auto& e : elements)
      if (e.location == length_) J += e.inertia;
    const MobilizedBody::Pin tip(parent, Transform(Vec3(h, 0, 0)),
                                 Body::Rigid(MassProperties(beam.tip_mass, Vec3(0), Inertia(Vec3(0, J, J)))), Transform());
    const auto j = static_cast<std::size_t>(n);
    joints.push_back({tip.getMobilizedBodyIndex(), 0, lumping_.stiffness[j], lumping_.damping[j]});
    tip_body_ = tip.getMobilizedBodyIndex();
  }
  if (k_theta_end[1] > 0.0) {
    // On the tip body (its angle is the end slope), else in series with the last cell.
    double k = k_theta_end[1], c = c_theta_end[1];
    if (!tip_body) series(k_theta_end[1], c_theta_end[1], lumping_.stiffness[static_cast<std::size_t>(n)],
                          lumping_.damping[static_cast<std::size_t>(n)], k, c);
    anchors.push_back({tip_body ? tip_body_ : parent.getMobilizedBodyIndex(), k, c});
  }
  for (const auto& [i, e] : interior_rotation)  // a dashpot alone at s = L acts on the tip body where there is one
    anchors.push_back({tip_body && e.location == length_ ? tip_body_ : segment_bodies_[static_cast<std::size_t>(i)], e.k_theta,
                       e.c_theta});
  for (std::size_t k = 0; k < points.size(); ++k) points[k].body = segment_bodies_[static_cast<std::size_t>(point_bar[k])];
  // A lumped attachment: its mass a particle on a Slider from ground along y at the station (rest
  // at y = 0), its spring-dashpot to the bar's station a PointSpring between the two, its spring to
  // ground the slider's own spring (docs/theory.md §2.5).
  for (const auto& e : elements) {
    if (!(e.lumped_mass > 0.0)) continue;
    double x = 0.0;
    const int i = bar_of(e.location, x);
    const MobilizedBody::Slider mass(matter_.updGround(), Transform(Rotation(Pi / 2, ZAxis), Vec3(e.location, 0, 0)),
                                     Body::Rigid(MassProperties(e.lumped_mass, Vec3(0), Inertia(0))), Transform());
    Station at;
    at.body = mass.getMobilizedBodyIndex();
    at.p_RS0 = Vec3(e.location, 0, 0);
    lumped_[e.name] = at;
    PointSpring coupling{segment_bodies_[static_cast<std::size_t>(i)], Vec3(x, 0, 0), e.lumped_k, e.lumped_c,
                         mass.getMobilizedBodyIndex(), Vec3(0.0)};
    points.push_back(coupling);
    if (e.lumped_k_ground > 0.0) joints.push_back({mass.getMobilizedBodyIndex(), 0, e.lumped_k_ground, 0.0});
  }
  if (beam.right != io::EndCondition::Free) {
    Constraint::PointInPlane(matter_.updGround(), UnitVec3(0, 1, 0), 0.0, parent, Vec3(h, 0, 0));
    if (beam.right == io::EndCondition::Clamped) {
      const auto j = static_cast<std::size_t>(n);
      anchors.push_back({parent.getMobilizedBodyIndex(), lumping_.stiffness[j], lumping_.damping[j]});
    }
  }
  joint_springs_ = joints;
  Force::Custom(forces_, new JointForces(matter_, std::move(joints), std::move(anchors), {}, std::move(points)));
}

Station BeamChain::attachment_station(const std::string& name) const {
  const auto it = lumped_.find(name);
  return it == lumped_.end() ? Station{} : it->second;
}

// The strain gauge at s (sensors.h): the joints at j h and (j + 1) h around s, with their Hencky
// springs (hencky.h) of the beam the chain simulates.
void BeamChain::resolve_strain(const io::SensorSpec& se, ResolvedSensor& r) const {
  const io::BeamSpec& beam = beam_;
  const Structure& st = *this;
  const int n = st.segments();
  const double h = st.length() / n;
  const PiecewiseField EI{beam.length, beam.EI};
  const HenckyLumping lumping = hencky_lumping(n, EI, PiecewiseField{beam.length, {beam.c_kv}});
  const auto& seg = st.segment_bodies();
  auto joint = [&](int j) {
    ResolvedSensor::Joint jt;
    // An end's rotational spring (supports, attachments) acts in series with the end cell's: the
    // joint carries the series stiffness (beam_chain.h).
    if (j == 0) {
      if (beam.left == io::EndCondition::Clamped) jt = {MobilizedBodyIndex(), seg.front(), lumping.stiffness.front()};
      else if (const double k = end_series_stiffness(beam, 0, lumping.stiffness.front()); k > 0.0)
        jt = {MobilizedBodyIndex(), seg.front(), k};
    } else if (j == n) {
      if (st.tip_body().isValid()) jt = {seg.back(), st.tip_body(), lumping.stiffness.back()};
      else if (beam.right == io::EndCondition::Clamped) jt = {seg.back(), MobilizedBodyIndex(), lumping.stiffness.back()};
      else if (const double k = end_series_stiffness(beam, 1, lumping.stiffness.back()); k > 0.0)
        jt = {seg.back(), MobilizedBodyIndex(), k};
    } else {
      jt = {seg[static_cast<std::size_t>(j - 1)], seg[static_cast<std::size_t>(j)], lumping.stiffness[static_cast<std::size_t>(j)]};
    }
    return jt;
  };
  const int j = std::clamp(static_cast<int>(std::floor(se.location / h)), 0, n - 1);
  r.joints[0] = joint(j);
  r.joints[1] = joint(j + 1);
  r.weight = std::clamp(se.location / h - j, 0.0, 1.0);
  r.scale = -se.field("offset") / EI.at(se.location);
}

std::unique_ptr<Structure> make_beam_chain(const io::Scenario& sc, int segments) {
  return std::make_unique<BeamChain>(sc.beam, segments);
}

}  // namespace scoleid::model
