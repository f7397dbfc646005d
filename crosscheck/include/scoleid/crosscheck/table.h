#pragma once
// One table, three renderings: aligned text for the terminal, CSV for other tools, and Markdown
// for report.md. Cells are already-formatted strings; numbers are formatted by `number`.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace scoleid::crosscheck {

struct Table {
  std::string title;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  std::string text() const;
  std::string csv() const;
  std::string markdown() const;
};

// %.*g with `digits` significant digits; NaN and infinities as "nan", "inf" (CSV readers
// understand them); `percent` multiplies by 100 and appends nothing (the header says %).
std::string number(double v, int digits = 6);
std::string percent(double v, int digits = 3);
// A number for JSON: NaN and infinities (not representable there) become null.
nlohmann::json json_number(double v);

}  // namespace scoleid::crosscheck
