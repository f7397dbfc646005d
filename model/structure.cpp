#include "scoleid/model/structure.h"

#include <algorithm>
#include <cmath>

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

}  // namespace scoleid::model
