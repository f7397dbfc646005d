// libFuzzer harness: arbitrary bytes as scenario YAML. The only acceptable failure is InputError;
// any other exception escapes and libFuzzer reports it as a crash (uncaught exception -> abort).
#include <cstddef>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "scoleid/io/error.h"
#include "scoleid/io/scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const scoleid::io::Scenario sc = scoleid::io::parse_scenario(text, "fuzz");
    // The echo path: every field of a parsed scenario must serialise.
    const std::string echo = scoleid::io::to_json(sc).dump();
    (void)echo;
  } catch (const scoleid::io::InputError&) {
  }
  return 0;
}
