// libFuzzer harness: arbitrary bytes as a Universal File. Only InputError may escape the reader,
// and what it returns must be consistent.
#include <cstddef>
#include <cstdint>
#include <set>
#include <string>

#include "scoleid/io/error.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/uff.h"

namespace {

void check_functions(const scoleid::io::uff::File& f) {
  for (const auto& g : f.functions) {
    if (g.x.size() != g.points || g.re.size() != g.points) __builtin_trap();
    if (!g.im.empty() && g.im.size() != g.re.size()) __builtin_trap();
    if (g.is_complex() == g.im.empty()) __builtin_trap();
    if (g.points == 0 || static_cast<double>(g.points) > scoleid::io::limits::kMaxSamples) __builtin_trap();
    if (g.value_bytes != 4 && g.value_bytes != 8) __builtin_trap();
    if (g.record == 0 || g.record > f.datasets) __builtin_trap();
  }
  const auto names = scoleid::io::uff::channel_names(f);
  if (names.size() != f.functions.size()) __builtin_trap();
  if (std::set<std::string>(names.begin(), names.end()).size() != names.size()) __builtin_trap();
  for (const auto& g : f.functions) (void)scoleid::io::uff::ordinate_unit(g), (void)scoleid::io::uff::abscissa_unit(g);
}

void check_shapes(const scoleid::io::uff::File& f) {
  for (const auto& s : f.shapes) {
    if (s.values.size() != s.nodes.size()) __builtin_trap();
    if (!s.values_im.empty() && s.values_im.size() != s.nodes.size()) __builtin_trap();
    if (s.is_complex() && s.values_im.size() != s.nodes.size()) __builtin_trap();
    for (const auto& v : s.values)
      if (v.size() != static_cast<std::size_t>(s.values_per_node)) __builtin_trap();
    for (const auto& v : s.values_im)
      if (v.size() != static_cast<std::size_t>(s.values_per_node)) __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  (void)scoleid::io::uff::looks_like_uff(text);
  try {
    const scoleid::io::uff::File f = scoleid::io::uff::parse(text, "fuzz.uff");
    if (f.datasets == 0) __builtin_trap();  // an empty file is an error, not an empty result
    if (f.functions.size() + f.shapes.size() + f.skipped.size() > f.datasets) __builtin_trap();
    check_functions(f);
    check_shapes(f);
  } catch (const scoleid::io::InputError&) {
  }
  return 0;
}
