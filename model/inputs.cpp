#include "scoleid/model/inputs.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "scoleid/io/error.h"

namespace scoleid::model {

using namespace SimTK;

namespace {
// The shortest time scale of the smooth (curved) terms of g active at t; infinity where g is
// piecewise linear (io/signal.h conventions: each term is active on [t0, t0 + length)).
double smooth_time_scale(const io::Signal& g, double t) {
  using T = io::SignalTerm::Type;
  double scale = std::numeric_limits<double>::infinity();
  for (const auto& s : g.terms()) {
    const double u = t - s.t0;
    if (u < 0.0) continue;
    switch (s.type) {
      case T::Sine:
        if (s.duration <= 0.0 || u < s.duration) scale = std::min(scale, 1.0 / s.f0);
        break;
      case T::Chirp:
        if (u < s.duration && std::max(s.f0, s.f1) > 0.0) scale = std::min(scale, 1.0 / std::max(s.f0, s.f1));
        break;
      case T::Haversine:
        if (u < s.width) scale = std::min(scale, s.width);
        break;
      case T::Multisine:
        if ((s.duration <= 0.0 || u < s.duration) && !io::multisine_lines(s).empty())
          scale = std::min(scale, 1.0 / io::multisine_lines(s).back());
        break;
      default: break;  // step, pulse, bang-bang, table: linear between breakpoints
    }
  }
  return scale;
}
}  // namespace

LaggedSignal::LaggedSignal(io::Signal command, double tau, double t_end, const std::string& source,
                           const std::string& field)
    : g_(std::move(command)), tau_(tau), breakpoints_(g_.breakpoints()) {
  if (!(tau_ > 0.0)) throw std::invalid_argument("LaggedSignal: tau must be > 0");
  segs_ = segments(0.0, std::max(t_end, 0.0));
  double count = 1.0;
  for (const auto& s : segs_) count += static_cast<double>(s.n);
  if (!(count <= kMaxNodes))
    io::fail_field(source, field,
                   "gives " + io::format_value(count) + " nodes for the servo lag's force history over " +
                       io::format_value(t_end) + " s, more than the limit of " + io::format_value(kMaxNodes),
                   g_.describe());
  f_.reserve(static_cast<std::size_t>(count));
  f_.push_back(g_(0.0));  // f(0) = f_cmd(0)
  for (auto& s : segs_) {
    s.first = f_.size() - 1;
    for (std::size_t k = 0; k < s.n; ++k) {
      const double t0 = s.a + static_cast<double>(k) * s.h;
      const double t1 = k + 1 == s.n ? s.b : s.a + static_cast<double>(k + 1) * s.h;
      f_.push_back(advance(f_.back(), t0, t1, k + 1 == s.n, t1 - t0));
    }
  }
}

std::vector<LaggedSignal::Segment> LaggedSignal::segments(double t0, double t1) const {
  std::vector<double> ends{t0};
  for (double b : breakpoints_)
    if (b > t0 && b < t1) ends.push_back(b);
  ends.push_back(t1);
  std::vector<Segment> out;
  for (std::size_t i = 0; i + 1 < ends.size(); ++i) {
    Segment s;
    s.a = ends[i];
    s.b = ends[i + 1];
    if (!(s.b > s.a)) continue;
    const double scale = smooth_time_scale(g_, 0.5 * (s.a + s.b));
    const double n = std::isfinite(scale) ? std::ceil((s.b - s.a) * kNodesPerScale / scale) : 1.0;
    s.n = static_cast<std::size_t>(std::min(std::max(n, 1.0), kMaxNodes + 1.0));
    s.h = (s.b - s.a) / static_cast<double>(s.n);
    out.push_back(s);
  }
  return out;
}

double LaggedSignal::advance(double f0, double t0, double t1, bool at_break, double x) const {
  const double H = t1 - t0;
  const double g0 = g_(t0);
  const double gm = g_(t0 + 0.5 * H);
  const double g1 = g_(at_break ? std::nextafter(t1, t0) : t1);
  const double s1 = (4.0 * gm - 3.0 * g0 - g1) / H;
  const double s2 = 2.0 * (g0 - 2.0 * gm + g1) / (H * H);
  const double z = x / tau_;
  const double one_minus_e = -std::expm1(-z);
  const double I1 = z - one_minus_e;
  const double I2 = z * z - 2.0 * I1;
  return std::exp(-z) * f0 + one_minus_e * g0 + tau_ * s1 * I1 + tau_ * tau_ * s2 * I2;
}

double LaggedSignal::operator()(double t) const {
  if (!(t > 0.0) || segs_.empty()) return f_.front();
  const Segment& last = segs_.back();
  if (t > last.b) {
    // Beyond the grid: march from its last node.
    double f = f_.back();
    for (const auto& s : segments(last.b, t))
      for (std::size_t k = 0; k < s.n; ++k) {
        const double t0 = s.a + static_cast<double>(k) * s.h;
        const double t1 = k + 1 == s.n ? s.b : s.a + static_cast<double>(k + 1) * s.h;
        f = advance(f, t0, t1, k + 1 == s.n && t1 < t, t1 - t0);
      }
    return f;
  }
  auto it = std::upper_bound(segs_.begin(), segs_.end(), t, [](double v, const Segment& s) { return v < s.a; });
  const Segment& s = *(it - 1);
  std::size_t k = static_cast<std::size_t>(std::floor((t - s.a) / s.h));
  k = std::min(k, s.n - 1);
  const double t0 = s.a + static_cast<double>(k) * s.h;
  const double t1 = k + 1 == s.n ? s.b : s.a + static_cast<double>(k + 1) * s.h;
  if (t == t0) return f_[s.first + k];
  if (t == t1) return f_[s.first + k + 1];
  return advance(f_[s.first + k], t0, t1, k + 1 == s.n, t - t0);
}

namespace {
// A scenario that passed io::validate_scenario holds only sites, kinds and directions the
// structure reads (io/<kind>_kind.cpp, KindTable::check); anything else is a caller's defect.
[[noreturn]] void unchecked(const std::string& field) {
  throw std::logic_error("resolve_inputs: " + field + " is not one this structure reads (io::validate_scenario refuses it)");
}
}  // namespace

std::vector<AppliedInput> resolve_inputs(const io::Scenario& sc, const Structure& st) {
  std::vector<AppliedInput> out;
  const bool planar = st.planar();
  for (std::size_t i = 0; i < sc.inputs.size(); ++i) {
    const io::InputSpec& in = sc.inputs[i];
    const std::string field = "inputs[" + std::to_string(i) + "]";
    AppliedInput a;
    a.signal = in.signal;
    a.kind = in.kind == io::InputKind::Moment ? AppliedInput::Kind::Moment : AppliedInput::Kind::Force;
    const Vec3 d(in.direction[0], in.direction[1], in.direction[2]);
    if (planar) {
      if (in.at != st.planar_site())
        unchecked(field + ".at");
      a.station = st.station_at(in.location);
      if (!in.attachment.empty()) {  // on the attachment's lumped mass (docs/theory.md §2.5)
        a.station = st.attachment_station(in.attachment);
        if (!a.station.body.isValid())
          unchecked(field + ".attachment");
      }
      a.d_R = a.kind == AppliedInput::Kind::Moment ? Vec3(0, 0, 1) : Vec3(0, 1, 0);
    } else if (in.at == io::Site::Beam) {
      unchecked(field + ".at");
    } else if (io::actuator_index(in.at) >= 0) {
      const int k = io::actuator_index(in.at) + 1;
      a.kind = AppliedInput::Kind::Slider;
      a.slider_x = st.actuator_slider(k, 0);
      a.slider_y = st.actuator_slider(k, 1);
      if (!a.slider_x.isValid())
        unchecked(field + ".at");
      if (in.kind != io::InputKind::Force)
        unchecked(field + ".kind");
      if (std::abs(d[2]) > 1e-12 || d.norm() == 0)
        unchecked(field + ".direction");
      a.d_R = d;
      if (st.actuator_lag() > 0)
        a.lagged = std::make_shared<const LaggedSignal>(in.signal, st.actuator_lag(), sc.simulation.duration,
                                                        sc.source, field + ".signal");
    } else {
      if (d.norm() == 0)
        unchecked(field + ".direction");
      a.d_R = d;
      a.station = st.site_station(in.at, in.location);
      if (!a.station.body.isValid())
        unchecked(field + ".at");
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
    const Real f = a.lagged ? (*a.lagged)(t) : a.signal(t);
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
