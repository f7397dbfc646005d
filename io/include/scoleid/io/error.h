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
  // A NUL in the message (a key or a name that holds one) is shown as \x00: what() is read as a
  // C string, which would end there and lose the field and the value.
  explicit InputError(const std::string& what) : std::runtime_error(without_nul(what)) {}

private:
  static std::string without_nul(const std::string& s) {
    if (s.find('\0') == std::string::npos) return s;
    std::string out;
    for (char c : s) c == '\0' ? out += "\\x00" : out += c;
    return out;
  }
};

// Formats a value for an error message the way a user typed it (shortest round-trip form).
std::string format_value(double v);

// "<source>: <field> <requirement>, got <value>"
[[noreturn]] void fail_field(const std::string& source, const std::string& field,
                             const std::string& requirement, const std::string& got);

}  // namespace scoleid::io
