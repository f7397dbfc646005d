// libFuzzer harness: arbitrary bytes as an NI TDMS file (io/tdms.h). Only InputError may escape the
// reader, and a table that loaded is well formed.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "scoleid/io/error.h"
#include "scoleid/io/tdms.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    const scoleid::io::DataTable tab = scoleid::io::read_tdms_bytes(bytes, "fuzz.tdms");
    if (tab.t.size() < 2 || tab.names.empty() || tab.columns.size() != tab.names.size() || tab.units.size() != tab.names.size())
      __builtin_trap();
    for (std::size_t k = 0; k < tab.t.size(); ++k)
      if (!std::isfinite(tab.t[k]) || (k > 0 && !(tab.t[k] > tab.t[k - 1]))) __builtin_trap();
    for (const auto& c : tab.columns) {
      if (c.size() != tab.t.size()) __builtin_trap();
      for (double v : c)
        if (!std::isfinite(v)) __builtin_trap();
    }
  } catch (const scoleid::io::InputError&) {
  }
  return 0;
}
