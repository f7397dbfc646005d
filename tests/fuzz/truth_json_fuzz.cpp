// libFuzzer harness: arbitrary bytes as truth.json. The JSON parse itself is no-throw; what it
// accepts goes to truth_meta_from_json, from which only InputError may escape.
#include <cstddef>
#include <cstdint>

#include <nlohmann/json.hpp>

#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const nlohmann::json j = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return 0;
  try {
    const scoleid::io::TruthMeta m = scoleid::io::truth_meta_from_json(j, "fuzz.json");
    // Round trip through the writer's representation.
    (void)scoleid::io::to_json(m).dump();
  } catch (const scoleid::io::InputError&) {
  }
  return 0;
}
