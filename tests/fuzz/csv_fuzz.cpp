// libFuzzer harness: arbitrary bytes as a data CSV, in any of its dialects (docs/data.md §1.1), read
// as it is and with a named time column and time unit (chosen by the first byte). Only InputError
// may escape the loader.
#include <cstddef>
#include <cstdint>
#include <string>

#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    scoleid::io::CsvOptions options;
    if (size > 0 && (data[0] & 1)) {
      options.time_column = "Time [s]";
      options.time_unit = "ms";
    }
    const scoleid::io::DataTable tab = scoleid::io::read_csv_text(text, "fuzz.csv", options);
    if (!tab.units.empty() && tab.units.size() != tab.names.size()) __builtin_trap();
    for (std::size_t k = 1; k < tab.t.size(); ++k)
      if (!(tab.t[k] > tab.t[k - 1])) __builtin_trap();
    // A table that loaded is well formed: one column per name, each as long as t.
    if (tab.columns.size() != tab.names.size()) __builtin_trap();
    for (const auto& c : tab.columns)
      if (c.size() != tab.t.size()) __builtin_trap();
    if (!tab.names.empty()) (void)tab.interpolate(0, 0.5 * (tab.t.front() + tab.t.back()));
  } catch (const scoleid::io::InputError&) {
  }
  return 0;
}
