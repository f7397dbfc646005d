// libFuzzer harness: arbitrary bytes as a LabVIEW Measurement file (io/lvm.h). Only InputError may
// escape the reader, and a table that loaded is well formed.
#include <cstddef>
#include <cstdint>
#include <string>

#include "scoleid/io/error.h"
#include "scoleid/io/lvm.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const scoleid::io::DataTable tab = scoleid::io::read_lvm_text(text, "fuzz.lvm");
    if (tab.t.size() < 2 || tab.columns.size() != tab.names.size() || tab.units.size() != tab.names.size()) __builtin_trap();
    for (std::size_t k = 1; k < tab.t.size(); ++k)
      if (!(tab.t[k] > tab.t[k - 1])) __builtin_trap();
    for (const auto& c : tab.columns)
      if (c.size() != tab.t.size()) __builtin_trap();
  } catch (const scoleid::io::InputError&) {
  }
  return 0;
}
