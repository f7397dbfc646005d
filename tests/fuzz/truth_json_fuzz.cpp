// libFuzzer harness: arbitrary bytes as truth.json, read as the programs read it: parse_json_text
// (duplicate keys refused through the parser's callback), then truth_meta_from_json; from either
// only InputError may escape.
#include <cstddef>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"
#include "scoleid/io/input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const nlohmann::json j =
        scoleid::io::parse_json_text(std::string(reinterpret_cast<const char*>(data), size), "fuzz.json");
    const scoleid::io::TruthMeta m = scoleid::io::truth_meta_from_json(j, "fuzz.json");
    // Round trip through the writer's representation.
    (void)scoleid::io::to_json(m).dump();
  } catch (const scoleid::io::InputError&) {
  }
  return 0;
}
