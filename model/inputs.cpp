#include "scoleid/model/inputs.h"

#include <cmath>

#include "scoleid/io/error.h"

namespace scoleid::model {

using namespace SimTK;

std::vector<AppliedInput> resolve_inputs(const io::Scenario& sc, const Structure& st) {
  std::vector<AppliedInput> out;
  const bool beam = st.kind() == "beam";
  for (std::size_t i = 0; i < sc.inputs.size(); ++i) {
    const io::InputSpec& in = sc.inputs[i];
    const std::string field = "inputs[" + std::to_string(i) + "]";
    AppliedInput a;
    a.signal = in.signal;
    a.kind = in.kind == "moment" ? AppliedInput::Kind::Moment : AppliedInput::Kind::Force;
    const Vec3 d(in.direction[0], in.direction[1], in.direction[2]);
    if (beam) {
      if (in.at != "beam")
        io::fail_field(sc.source, field + ".at", "must be 'beam' for a beam structure", "'" + in.at + "'");
      a.station = st.station_at(in.location);
      a.d_R = a.kind == AppliedInput::Kind::Moment ? Vec3(0, 0, 1) : Vec3(0, 1, 0);
    } else if (in.at == "beam") {
      io::fail_field(sc.source, field + ".at", "must not be 'beam' for a scole structure", "'beam'");
    } else if (in.at.rfind("actuator", 0) == 0) {
      const int k = in.at == "actuator1" ? 1 : 2;
      a.kind = AppliedInput::Kind::Slider;
      a.slider_x = st.actuator_slider(k, 0);
      a.slider_y = st.actuator_slider(k, 1);
      if (!a.slider_x.isValid())
        io::fail_field(sc.source, field + ".at", "names an actuator the configuration does not have",
                       "'" + in.at + "'");
      if (in.kind != "force")
        io::fail_field(sc.source, field + ".kind", "must be 'force' for a proof-mass actuator", "'" + in.kind + "'");
      if (std::abs(d[2]) > 1e-12 || d.norm() == 0)
        io::fail_field(sc.source, field + ".direction", "must lie in the actuator plane (x, y)",
                       "[" + io::format_value(d[0]) + ", " + io::format_value(d[1]) + ", " + io::format_value(d[2]) + "]");
      a.d_R = d;
    } else {
      if (d.norm() == 0)
        io::fail_field(sc.source, field + ".direction", "must be given (x, y, z or a 3-vector)", "none");
      a.d_R = d;
      a.station = in.at == "mast" ? st.station_at(in.location) : st.named_station(in.at);
      if (!a.station.body.isValid())
        io::fail_field(sc.source, field + ".at", "is not a body of this structure", "'" + in.at + "'");
    }
    out.push_back(a);
  }
  return out;
}

InputForces::InputForces(const SimbodyMatterSubsystem& matter, MobilizedBodyIndex reference,
                         std::vector<AppliedInput> inputs)
    : matter_(matter), reference_(reference), inputs_(std::move(inputs)) {}

void InputForces::calcForce(const State& state, Vector_<SpatialVec>& body_forces, Vector_<Vec3>&,
                            Vector& mobility_forces) const {
  const Real t = state.getTime();
  const Rotation& R_GR = matter_.getMobilizedBody(reference_).getBodyRotation(state);
  for (const auto& a : inputs_) {
    const Real f = a.signal(t);
    if (f == 0.0) continue;
    switch (a.kind) {
      case AppliedInput::Kind::Force: {
        const MobilizedBody& b = matter_.getMobilizedBody(a.station.body);
        b.applyForceToBodyPoint(state, a.station.p_BS, R_GR * (f * a.d_R), body_forces);
        break;
      }
      case AppliedInput::Kind::Moment:
        matter_.getMobilizedBody(a.station.body).applyBodyTorque(state, R_GR * (f * a.d_R), body_forces);
        break;
      case AppliedInput::Kind::Slider:
        matter_.getMobilizedBody(a.slider_x).applyOneMobilityForce(state, 0, f * a.d_R[0], mobility_forces);
        matter_.getMobilizedBody(a.slider_y).applyOneMobilityForce(state, 0, f * a.d_R[1], mobility_forces);
        break;
    }
  }
}

}  // namespace scoleid::model
