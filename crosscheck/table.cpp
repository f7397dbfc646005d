#include "scoleid/crosscheck/table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace scoleid::crosscheck {

namespace {
std::string csv_cell(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}
}  // namespace

std::string Table::text() const {
  std::vector<std::size_t> w(header.size(), 0);
  for (std::size_t j = 0; j < header.size(); ++j) w[j] = header[j].size();
  for (const auto& r : rows)
    for (std::size_t j = 0; j < r.size() && j < w.size(); ++j) w[j] = std::max(w[j], r[j].size());
  std::string out;
  if (!title.empty()) out += title + "\n";
  auto line = [&](const std::vector<std::string>& cells) {
    for (std::size_t j = 0; j < w.size(); ++j) {
      const std::string c = j < cells.size() ? cells[j] : "";
      out += (j ? "  " : "") + std::string(w[j] - c.size(), ' ') + c;
    }
    out += "\n";
  };
  line(header);
  std::size_t total = 0;
  for (auto x : w) total += x + 2;
  out += std::string(total > 2 ? total - 2 : 0, '-') + "\n";
  for (const auto& r : rows) line(r);
  return out;
}

std::string Table::csv() const {
  std::string out;
  for (std::size_t j = 0; j < header.size(); ++j) out += (j ? "," : "") + csv_cell(header[j]);
  out += "\n";
  for (const auto& r : rows) {
    for (std::size_t j = 0; j < r.size(); ++j) out += (j ? "," : "") + csv_cell(r[j]);
    out += "\n";
  }
  return out;
}

std::string Table::markdown() const {
  std::string out;
  if (!title.empty()) out += "**" + title + "**\n\n";
  out += "|";
  for (const auto& h : header) out += " " + h + " |";
  out += "\n|";
  for (std::size_t j = 0; j < header.size(); ++j) out += "---:|";
  out += "\n";
  for (const auto& r : rows) {
    out += "|";
    for (const auto& c : r) out += " " + c + " |";
    out += "\n";
  }
  return out;
}

std::string number(double v, int digits) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

std::string percent(double v, int digits) { return number(100.0 * v, digits); }

nlohmann::json json_number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace scoleid::crosscheck
