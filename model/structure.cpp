#include "scoleid/model/structure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace scoleid::model {

Station Structure::station_at(double s) const {
  const int n = segments();
  const double h = length_ / n;
  const int i = std::clamp(static_cast<int>(std::floor(s / h)), 0, n - 1);
  Station st;
  st.body = segment_bodies_[static_cast<std::size_t>(i)];
  st.p_BS = axis_B_ * (s - i * h);
  st.p_RS0 = root_R_ + axis_R_ * s;
  return st;
}

Station Structure::named_station(io::Site) const { return {}; }

Station Structure::attachment_station(const std::string&) const { return {}; }

SimTK::MobilizedBodyIndex Structure::actuator_slider(int, int) const { return {}; }

void Structure::resolve_strain(const io::SensorSpec&, ResolvedSensor&) const {
  throw std::logic_error("Structure::resolve_strain: this structure has no strain gauges (io::reads)");
}

std::string Structure::segment_name(int i) const {
  const int n = segments();
  const double h = length_ / n;
  char buf[96];
  std::snprintf(buf, sizeof buf, " (s = %.6g to %.6g)", i * h, (i + 1) * h);
  return chain_name() + " segment " + std::to_string(i + 1) + " of " + std::to_string(n) + buf;
}

}  // namespace scoleid::model
