#include "scoleid/io/input_file.h"

#include <yaml-cpp/yaml.h>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <set>
#include <vector>

#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/validation.h"

namespace scoleid::io {

InputFileStream::InputFileStream(const std::string& path, const std::string& where) : std::istream(nullptr) {
  rdbuf(&buf_);
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(one_line(where + ": is a directory"));
  for (;;) {
    buf_.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (buf_.fd >= 0 || errno != EINTR) break;
    check_interrupt();  // a signal while blocked opening a FIFO
  }
  if (buf_.fd < 0) {
    check_interrupt();
    throw InputError(one_line(where + ": cannot be opened"));
  }
}

std::string file_head(const std::string& path, std::size_t bytes) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return {};
  std::ifstream in(path, std::ios::binary);
  std::string head(bytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head;
}

InputFileStream::~InputFileStream() {
  if (buf_.fd >= 0) ::close(buf_.fd);
}

InputFileStream::Buf::int_type InputFileStream::Buf::underflow() {
  if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
  for (;;) {
    const ssize_t n = ::read(fd, data, sizeof data);
    if (n > 0) {
      setg(data, data, data + n);
      return traits_type::to_int_type(*gptr());
    }
    if (n == 0) return traits_type::eof();
    if (errno != EINTR) return traits_type::eof();
    check_interrupt();
  }
}

std::string read_text_file(const std::string& path, const std::string& what, std::size_t max_bytes) {
  const std::string where = what + " '" + path + "'";
  InputFileStream in(path, where);
  std::string text;
  std::vector<char> chunk(std::size_t{1} << 16);
  while (in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    text.append(chunk.data(), static_cast<std::size_t>(in.gcount()));
    if (text.size() > max_bytes)
      throw InputError(one_line(where + ": is longer than " + std::to_string(max_bytes >> 20) +
                                " MiB, the limit for an input file"));
    check_interrupt();
  }
  if (in.bad()) throw InputError(one_line(where + ": cannot be read"));
  return text;
}

nlohmann::json parse_json_text(const std::string& text, const std::string& source) {
  using nlohmann::json;
  // The keys seen in each open object, and the path to it (object keys; "[]" for array elements).
  std::vector<std::set<std::string>> keys;
  std::vector<std::string> path;
  std::string pending;  // the key whose value is being parsed
  auto here = [&] {
    std::string p;
    for (const auto& s : path) p += (p.empty() || s == "[]" ? "" : ".") + s;
    return p;
  };
  const json::parser_callback_t cb = [&](int depth, json::parse_event_t event, json& parsed) {
    // Deeper than any file of ours: refused before the nesting reaches code that recurses over it.
    if (depth > kMaxNesting) throw InputError(one_line(source + ": nested deeper than " + std::to_string(kMaxNesting) + " levels"));
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        if (!keys.empty() || !path.empty() || !pending.empty()) path.push_back(pending.empty() ? "[]" : pending);
        pending.clear();
        keys.emplace_back();
        break;
      case json::parse_event_t::key: {
        const std::string k = parsed.get<std::string>();
        if (!keys.back().insert(k).second) {
          const std::string p = here();
          throw InputError(one_line(source + ": key '" + (p.empty() ? k : p + "." + k) + "' appears more than once"));
        }
        pending = k;
        break;
      }
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        keys.pop_back();
        if (!path.empty()) path.pop_back();
        pending.clear();
        break;
      case json::parse_event_t::value:
        pending.clear();
        break;
    }
    return true;
  };
  try {
    return json::parse(text, cb);
  } catch (const json::parse_error& e) {
    throw InputError(one_line(source + ": malformed JSON at byte " + std::to_string(e.byte)));
  } catch (const json::exception& e) {  // a number beyond double's range (out_of_range.406)
    throw InputError(one_line(source + ": malformed JSON (" + std::string(e.what()) + ")"));
  }
}

namespace {
std::string kind(const YAML::Node& n) {
  if (n.IsSequence()) return "list";
  if (n.IsMap()) return "map";
  if (n.IsNull()) return "null";
  return "'" + n.Scalar() + "'";
}

void check_node(const YAML::Node& n, const std::string& source, const std::string& path, bool allow_null,
                std::set<std::size_t>& seen) {
  const std::string at = path.empty() ? "document" : path;
  if (n.IsNull() && !path.empty() && !allow_null)
    fail_field(source, at, "has no value: give one, or leave the key out", "null");
  if (n.IsScalar()) {
    if (first_invalid_utf8(n.Scalar()) != std::string::npos)
      fail_field(source, at, "must be UTF-8 text", "a value with an invalid byte sequence");
    return;
  }
  if (!n.IsMap() && !n.IsSequence()) return;
  if (!seen.insert(static_cast<std::size_t>(n.Mark().pos)).second) return;
  if (n.IsMap()) {
    std::set<std::string> keys;
    for (const auto& kv : n) {
      if (!kv.first.IsScalar()) fail_field(source, at, "must have plain keys", "a " + kind(kv.first) + " as a key");
      const std::string key = kv.first.Scalar();
      if (first_invalid_utf8(key) != std::string::npos)
        fail_field(source, at, "must have UTF-8 keys", "a key with an invalid byte sequence");
      const std::string f = path.empty() ? key : path + "." + key;
      if (!keys.insert(key).second) fail_field(source, f, "appears more than once", "a second '" + key + "'");
      check_node(kv.second, source, f, allow_null, seen);
    }
  } else {
    for (std::size_t i = 0; i < n.size(); ++i)
      check_node(n[i], source, path + "[" + std::to_string(i) + "]", allow_null, seen);
  }
}
}  // namespace

void check_yaml_nesting(const std::string& text, const std::string& source) {
  int depth = 0;
  std::size_t line = 1;
  char quote = 0;
  bool comment = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      comment = false;
      if (quote == '\'') quote = 0;  // (a single-quoted scalar may span lines; a rough end is enough here)
      continue;
    }
    if (comment) continue;
    if (quote) {
      if (c == '\\' && quote == '"') ++i;
      else if (c == quote) quote = 0;
      continue;
    }
    if (c == '"' || c == '\'') quote = c;
    else if (c == '#' && (i == 0 || text[i - 1] == ' ' || text[i - 1] == '\t')) comment = true;
    else if (c == '[' || c == '{') {
      if (++depth > kMaxNesting)
        throw InputError(one_line(source + ": line " + std::to_string(line) + ": nested deeper than " +
                                  std::to_string(kMaxNesting) + " levels"));
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
}

void check_yaml_document(const YAML::Node& root, const std::string& source, bool allow_null) {
  std::set<std::size_t> seen;
  check_node(root, source, "", allow_null, seen);
}

}  // namespace scoleid::io
