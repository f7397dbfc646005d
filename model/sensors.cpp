#include "scoleid/model/sensors.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "scoleid/io/error.h"
#include "scoleid/model/hencky.h"

namespace scoleid::model {

using namespace SimTK;

namespace {
// Rotation at arc position s: linear between segment centres (see the header).
void interpolate_rotation(const Structure& st, double s, ResolvedSensor& r) {
  const int n = st.segments();
  const double h = st.length() / n;
  const double c = st.centre_coordinate(s);
  int i = static_cast<int>(std::floor(c));
  const auto& seg = st.segment_bodies();
  if (i < 0) {
    r.station.body = seg.front();
    return;
  }
  if (i >= n - 1) {
    r.station.body = seg.back();
    if (st.tip_body().isValid()) {
      r.second = st.tip_body();
      r.weight = std::min(1.0, (s - (st.length() - h / 2)) / (h / 2));
    }
    return;
  }
  r.station.body = seg[static_cast<std::size_t>(i)];
  r.second = seg[static_cast<std::size_t>(i + 1)];
  r.weight = c - i;
}

double rotation_about(const SimbodyMatterSubsystem& matter, const State& state, MobilizedBodyIndex b,
                      const MobilizedBody& R, const Vec3& d) {
  const Rotation R_RB = matter.getMobilizedBody(b).findBodyRotationInAnotherBody(state, R);
  const Vec4 aa = R_RB.convertRotationToAngleAxis();
  return aa[0] * dot(Vec3(aa[1], aa[2], aa[3]), d);
}

double joint_moment(const SimbodyMatterSubsystem& matter, const State& state, const ResolvedSensor::Joint& jt) {
  if (jt.k == 0.0) return 0.0;
  const MobilizedBody& G = matter.getGround();
  const Vec3 z(0, 0, 1);
  const double a = jt.a.isValid() ? rotation_about(matter, state, jt.a, G, z) : 0.0;
  const double b = jt.b.isValid() ? rotation_about(matter, state, jt.b, G, z) : 0.0;
  return jt.k * (b - a);
}
}  // namespace

namespace {
// A scenario that passed io::validate_scenario holds only sites, kinds and directions the
// structure reads (io/<kind>_kind.cpp, KindTable::check); anything else is a caller's defect.
[[noreturn]] void unchecked(const std::string& field) {
  throw std::logic_error("resolve_sensors: " + field + " is not one this structure reads (io::validate_scenario refuses it)");
}
}  // namespace

std::vector<ResolvedSensor> resolve_sensors(const io::Scenario& sc, const Structure& st) {
  std::vector<ResolvedSensor> out;
  const bool planar = st.planar();
  for (std::size_t i = 0; i < sc.sensors.size(); ++i) {
    const io::SensorSpec& se = sc.sensors[i];
    const std::string field = "sensors[" + std::to_string(i) + "]";
    ResolvedSensor r;
    using K = io::SensorKind;
    r.kind = se.kind;
    r.reference = st.reference_body();
    r.root_R = st.station_at(0.0).p_RS0;
    const Vec3 d(se.direction[0], se.direction[1], se.direction[2]);
    if (planar) {
      if (se.at != st.planar_site())
        unchecked(field + ".at");
      if (!io::reads(st.kind(), r.kind))
        unchecked(field + ".kind");
      r.station = st.station_at(se.location);
      r.d_R = r.kind == K::Rotation ? Vec3(0, 0, 1) : Vec3(0, 1, 0);
      if (r.kind == K::Rotation) interpolate_rotation(st, se.location, r);
      if (r.kind == K::Strain) st.resolve_strain(se, r);
      if (r.kind == K::RelativeDisplacement) r.apart = st.station_at(se.field("reference"));
    } else {
      if (!io::reads(st.kind(), r.kind))
        unchecked(field + ".kind");
      if (se.at == io::Site::Beam)
        unchecked(field + ".at");
      if (d.norm() == 0)
        unchecked(field + ".direction");
      r.d_R = d;
      r.station = st.site_station(se.at, se.location);
      if (st.chain_site(se.at) && r.kind == K::Rotation) interpolate_rotation(st, se.location, r);
      // The reference body's own motion is measured in the inertial frame.
      if (r.station.body.isValid() && r.station.body == st.reference_body()) r.reference = GroundIndex;
    }
    out.push_back(r);
  }
  return out;
}

double read_sensor(const SimbodyMatterSubsystem& matter, const State& state, const ResolvedSensor& s) {
  const MobilizedBody& B = matter.getMobilizedBody(s.station.body);
  const MobilizedBody& R = matter.getMobilizedBody(s.reference);
  using K = io::SensorKind;
  switch (s.kind) {
    case K::Displacement: {
      const Vec3 p_RP = B.findStationLocationInAnotherBody(state, s.station.p_BS, R);
      return dot(p_RP - s.station.p_RS0, s.d_R);
    }
    case K::Rotation: {
      const double a = rotation_about(matter, state, s.station.body, R, s.d_R);
      if (!s.second.isValid() || s.weight == 0.0) return a;
      return (1.0 - s.weight) * a + s.weight * rotation_about(matter, state, s.second, R, s.d_R);
    }
    case K::Velocity:
      return dot(B.findStationVelocityInAnotherBody(state, s.station.p_BS, R), s.d_R);
    case K::Acceleration: {
      const Vec3 a_G = B.findStationAccelerationInGround(state, s.station.p_BS);
      return dot(R.getBodyRotation(state).transpose() * a_G, s.d_R);
    }
    case K::LineOfSight: {
      const Vec3 p_RP = B.findStationLocationInAnotherBody(state, s.station.p_BS, R);
      const Vec3 u0 = (s.station.p_RS0 - s.root_R).normalize();
      const Vec3 u = (p_RP - s.root_R).normalize();
      return dot(cross(u0, u), s.d_R);
    }
    case K::RelativeDisplacement: {
      const MobilizedBody& A = matter.getMobilizedBody(s.apart.body);
      const Vec3 p_RP = B.findStationLocationInAnotherBody(state, s.station.p_BS, R);
      const Vec3 p_RA = A.findStationLocationInAnotherBody(state, s.apart.p_BS, R);
      return dot((p_RP - s.station.p_RS0) - (p_RA - s.apart.p_RS0), s.d_R);
    }
    case K::Strain:
      return s.scale * ((1.0 - s.weight) * joint_moment(matter, state, s.joints[0]) +
                        s.weight * joint_moment(matter, state, s.joints[1]));
  }
  return 0.0;
}

}  // namespace scoleid::model
