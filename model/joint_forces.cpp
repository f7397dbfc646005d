#include "scoleid/model/joint_forces.h"

#include <cmath>

namespace scoleid::model {

using namespace SimTK;

JointForces::JointForces(const SimbodyMatterSubsystem& matter, std::vector<JointSpring> joints,
                         std::vector<AnchorSpring> anchors, std::vector<RelativeDamper> relative,
                         std::vector<PointSpring> points, std::vector<RelativeSpring> relative_springs)
    : matter_(matter), joints_(std::move(joints)), anchors_(std::move(anchors)), relative_(std::move(relative)),
      points_(std::move(points)), relative_springs_(std::move(relative_springs)) {}

namespace {
double planar_angle(const Rotation& R_GB) { return std::atan2(R_GB[1][0], R_GB[0][0]); }
}  // namespace

void JointForces::index_joints(const State& state) const {
  std::call_once(indexed_, [&] {
    for (const auto& j : joints_) {
      const MobilizedBody& b = matter_.getMobilizedBody(j.body);
      q_at_.push_back(static_cast<int>(b.getFirstQIndex(state)) + j.which);
      u_at_.push_back(static_cast<int>(b.getFirstUIndex(state)) + j.which);
    }
  });
}

void JointForces::calcForce(const State& state, Vector_<SpatialVec>& body_forces, Vector_<Vec3>&,
                            Vector& mobility_forces) const {
  index_joints(state);
  const Vector& q = matter_.getQ(state);
  const Vector& u = matter_.getU(state);
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    const Real f = -joints_[i].k * q[q_at_[i]] - joints_[i].c * u[u_at_[i]];
    mobility_forces[u_at_[i]] += f;  // as MobilizedBody::applyOneMobilityForce adds it
  }
  for (const auto& a : anchors_) {
    const MobilizedBody& b = matter_.getMobilizedBody(a.body);
    const Real theta = planar_angle(b.getBodyRotation(state));
    const Real omega = b.getBodyAngularVelocity(state)[2];
    b.applyBodyTorque(state, Vec3(0, 0, -a.k * theta - a.c * omega), body_forces);
  }
  for (const auto& p : relative_springs_) {
    const MobilizedBody& b = matter_.getMobilizedBody(p.body);
    const MobilizedBody& o = matter_.getMobilizedBody(p.other);
    const Real dtheta = planar_angle(b.getBodyRotation(state)) - planar_angle(o.getBodyRotation(state));
    const Real domega = b.getBodyAngularVelocity(state)[2] - o.getBodyAngularVelocity(state)[2];
    const Vec3 torque(0, 0, -p.k * dtheta - p.c * domega);
    b.applyBodyTorque(state, torque, body_forces);
    o.applyBodyTorque(state, -torque, body_forces);
  }
  for (const auto& d : relative_) {
    const MobilizedBody& b = matter_.getMobilizedBody(d.body);
    const MobilizedBody& r = matter_.getMobilizedBody(d.reference);
    const Rotation& R_GR = r.getBodyRotation(state);
    const Vec3 w_R = ~R_GR * (b.getBodyAngularVelocity(state) - r.getBodyAngularVelocity(state));
    const Vec3 torque = R_GR * Vec3(-d.c[0] * w_R[0], -d.c[1] * w_R[1], -d.c[2] * w_R[2]);
    b.applyBodyTorque(state, torque, body_forces);
    r.applyBodyTorque(state, -torque, body_forces);
  }
  for (const auto& p : points_) {
    const MobilizedBody& b = matter_.getMobilizedBody(p.body);
    Real y = b.findStationLocationInGround(state, p.station)[1];
    Real v = b.findStationVelocityInGround(state, p.station)[1];
    if (p.other.isValid()) {
      const MobilizedBody& o = matter_.getMobilizedBody(p.other);
      y -= o.findStationLocationInGround(state, p.other_station)[1];
      v -= o.findStationVelocityInGround(state, p.other_station)[1];
      o.applyForceToBodyPoint(state, p.other_station, Vec3(0, p.k * y + p.c * v, 0), body_forces);
    }
    b.applyForceToBodyPoint(state, p.station, Vec3(0, -p.k * y - p.c * v, 0), body_forces);
  }
}

Real JointForces::calcPotentialEnergy(const State& state) const {
  Real e = 0.0;
  for (const auto& j : joints_) {
    const Real q = matter_.getMobilizedBody(j.body).getOneQ(state, j.which);
    e += 0.5 * j.k * q * q;
  }
  for (const auto& a : anchors_) {
    const Real theta = planar_angle(matter_.getMobilizedBody(a.body).getBodyRotation(state));
    e += 0.5 * a.k * theta * theta;
  }
  for (const auto& p : relative_springs_) {
    const Real dtheta = planar_angle(matter_.getMobilizedBody(p.body).getBodyRotation(state)) -
                        planar_angle(matter_.getMobilizedBody(p.other).getBodyRotation(state));
    e += 0.5 * p.k * dtheta * dtheta;
  }
  for (const auto& p : points_) {
    Real y = matter_.getMobilizedBody(p.body).findStationLocationInGround(state, p.station)[1];
    if (p.other.isValid()) y -= matter_.getMobilizedBody(p.other).findStationLocationInGround(state, p.other_station)[1];
    e += 0.5 * p.k * y * y;
  }
  return e;
}

}  // namespace scoleid::model
