#include "scoleid/io/uff_modes.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdlib>

#include "scoleid/io/error.h"

namespace scoleid::io {
namespace {

struct Station {
  int node = 0;
  int axis = 0;       // 0..5: X Y Z RX RY RZ
  double sign = 1.0;
};

// "<node><sign><axis>" or "<node>".
Station parse_station(const std::string& text, const std::string& source, const std::string& where) {
  Station s;
  std::size_t i = 0;
  while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
  if (i == 0 || i > 9) fail_field(source, where, "must be <node><+|-><X|Y|Z|RX|RY|RZ> (e.g. 12+Y)", "'" + text + "'");
  s.node = std::atoi(text.substr(0, i).c_str());
  if (i == text.size()) return s;
  if (text[i] != '+' && text[i] != '-') fail_field(source, where, "must be <node><+|-><X|Y|Z|RX|RY|RZ> (e.g. 12+Y)", "'" + text + "'");
  s.sign = text[i] == '-' ? -1.0 : 1.0;
  const std::string axis = text.substr(i + 1);
  const char* names[] = {"X", "Y", "Z", "RX", "RY", "RZ"};
  for (int a = 0; a < 6; ++a)
    if (axis == names[a]) {
      s.axis = a;
      return s;
    }
  fail_field(source, where, "must be <node><+|-><X|Y|Z|RX|RY|RZ> (e.g. 12+Y)", "'" + text + "'");
}

bool is_mode(const uff::Shape& s) {
  return (s.model_type == 0 || s.model_type == 1) && (s.analysis_type == 2 || s.analysis_type == 3 || s.analysis_type == 7) &&
         std::isfinite(s.frequency_hz) && s.frequency_hz > 0;
}

// The shape's real values at its nodes: complex shapes turned by the phase of the largest component.
std::vector<std::vector<double>> real_shape(const uff::Shape& s) {
  if (!s.is_complex()) return s.values;
  std::complex<double> big = 0.0;
  for (std::size_t n = 0; n < s.values.size(); ++n)
    for (std::size_t k = 0; k < s.values[n].size(); ++k) {
      const std::complex<double> v(s.values[n][k], s.values_im[n][k]);
      if (std::abs(v) > std::abs(big)) big = v;
    }
  const std::complex<double> turn = std::abs(big) > 0 ? std::conj(big) / std::abs(big) : 1.0;
  std::vector<std::vector<double>> out = s.values;
  for (std::size_t n = 0; n < s.values.size(); ++n)
    for (std::size_t k = 0; k < s.values[n].size(); ++k) out[n][k] = (std::complex<double>(s.values[n][k], s.values_im[n][k]) * turn).real();
  return out;
}

double value_at(const uff::Shape& s, const std::vector<std::vector<double>>& shape, const Station& st,
                const std::string& file, const std::string& station) {
  const auto it = std::find(s.nodes.begin(), s.nodes.end(), st.node);
  const std::string where = "UFF file '" + file + "': record " + std::to_string(s.record) + " (dataset 55, mode at " +
                            format_value(s.frequency_hz) + " Hz)";
  if (it == s.nodes.end()) throw InputError(where + ": has no node " + std::to_string(st.node) + " (station '" + station + "')");
  const auto& v = shape[static_cast<std::size_t>(it - s.nodes.begin())];
  if (static_cast<std::size_t>(st.axis) >= v.size())
    throw InputError(where + ": node " + std::to_string(st.node) + " has " + std::to_string(v.size()) +
                     " values, no axis for station '" + station + "'");
  return st.sign * v[static_cast<std::size_t>(st.axis)];
}

void check_options(const UffModesOptions& o) {
  if (!(o.frequency_std > 0 && o.frequency_std < 1))
    fail_field(o.source, "modes.frequency_std", "must be a relative standard deviation in (0, 1) (a Universal File states none)",
               format_value(o.frequency_std));
  if (!(o.damping_std >= 0 && std::isfinite(o.damping_std))) fail_field(o.source, "modes.damping_std", "must be >= 0", format_value(o.damping_std));
  if (!o.stations.empty() && !(o.shape_std > 0 && std::isfinite(o.shape_std)))
    fail_field(o.source, "modes.shape_std", "must be > 0 when there are stations", format_value(o.shape_std));
}

}  // namespace

ModalData modal_data_from_uff(const uff::File& file, const UffModesOptions& o) {
  check_options(o);
  std::vector<const uff::Shape*> modes;
  for (const auto& s : file.shapes)
    if (is_mode(s)) modes.push_back(&s);
  if (modes.empty())
    throw InputError("UFF file '" + file.source + "': no mode shape (dataset 55 of a normal or complex mode with a frequency)");
  std::stable_sort(modes.begin(), modes.end(), [](const uff::Shape* a, const uff::Shape* b) { return a->frequency_hz < b->frequency_hz; });
  std::vector<Station> stations;
  ModalData d;
  d.source = file.source;
  for (const auto& [name, text] : o.stations) {
    stations.push_back(parse_station(text, o.source, "modes.stations." + name));
    d.stations.push_back(name);
  }
  const bool damping = o.damping_std > 0;
  for (std::size_t m = 0; m < modes.size(); ++m) {
    const uff::Shape& s = *modes[m];
    ModalData::Mode mode;
    mode.label = static_cast<int>(m + 1);
    mode.frequency_hz = s.frequency_hz;
    mode.frequency_std_hz = o.frequency_std * s.frequency_hz;
    if (damping) {
      if (!std::isfinite(s.damping_ratio))
        throw InputError("UFF file '" + file.source + "': record " + std::to_string(s.record) + " (dataset 55): no damping ratio, but " +
                         o.source + " gives modes.damping_std");
      mode.damping_ratio = s.damping_ratio;
      mode.damping_std = o.damping_std;
    }
    const auto shape = real_shape(s);
    for (std::size_t k = 0; k < stations.size(); ++k) mode.shape.push_back(value_at(s, shape, stations[k], file.source, d.stations[k]));
    if (!stations.empty()) mode.shape_std = o.shape_std;
    d.modes.push_back(mode);
  }
  validate_modal_data(d);
  return d;
}

}  // namespace scoleid::io
