#pragma once
// Input errors: bad usage, bad scenario, bad data. Every tool maps InputError to exit code 2
// and prints its message as one line. The message always names the source (file or scenario),
// the field and the offending value.
#include <sstream>
#include <stdexcept>
#include <string>

namespace scoleid::io {

class InputError : public std::runtime_error {
public:
  explicit InputError(const std::string& what) : std::runtime_error(what) {}
};

// Formats a value for an error message the way a user typed it (shortest round-trip form).
std::string format_value(double v);

// "<source>: <field> <requirement>, got <value>"
[[noreturn]] void fail_field(const std::string& source, const std::string& field,
                             const std::string& requirement, const std::string& got);

}  // namespace scoleid::io
