#pragma once
// The shape of the cross-check's own JSON (report inputs, suite results), checked before any of it is
// used: a file edited or cut short gets one line naming the file, the field and what it holds
// (io::InputError, exit 2), never a crash or an assertion of the JSON library.
#include <string>

#include <nlohmann/json.hpp>

#include "scoleid/io/error.h"

namespace scoleid::crosscheck {

class Shape {
public:
  explicit Shape(std::string file) : file_(std::move(file)) {}
  [[noreturn]] void fail(const std::string& field, const std::string& want, const nlohmann::json* got) const {
    std::string g = got ? got->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) : "nothing";
    if (g.size() > 80) g = g.substr(0, 77) + "...";
    throw io::InputError(file_ + ": field '" + field + "' must be " + want + ", got " + g +
                         " (not as scole-crosscheck writes it: run its verb again)");
  }
  const nlohmann::json& at(const nlohmann::json& obj, const std::string& key, const std::string& field) const {
    if (!obj.is_object() || !obj.contains(key)) fail(field, "present", nullptr);
    return obj.at(key);
  }
  void text(const nlohmann::json& obj, const std::string& key, const std::string& where) const {
    const auto& v = at(obj, key, where + key);
    if (!v.is_string()) fail(where + key, "text", &v);
  }
  void flag(const nlohmann::json& obj, const std::string& key, const std::string& where) const {
    const auto& v = at(obj, key, where + key);
    if (!v.is_boolean()) fail(where + key, "true or false", &v);
  }
  void count(const nlohmann::json& obj, const std::string& key, const std::string& where) const {
    const auto& v = at(obj, key, where + key);
    if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() > 1000000000) fail(where + key, "a count", &v);
  }
  void number(const nlohmann::json& obj, const std::string& key, const std::string& where) const {
    const auto& v = at(obj, key, where + key);
    if (!v.is_number() && !v.is_null()) fail(where + key, "a number or null", &v);
  }
  // An array of `n` entries (n = 0: at least one) each passing `ok`, described as `what`.
  template <class Ok>
  const nlohmann::json& array(const nlohmann::json& obj, const std::string& key, const std::string& where, std::size_t n,
                              const char* what, Ok ok) const {
    const auto& v = at(obj, key, where + key);
    const std::string want = (n ? "an array of " + std::to_string(n) : std::string("a non-empty array of")) + " " + what;
    if (!v.is_array() || (n ? v.size() != n : v.empty())) fail(where + key, want, &v);
    for (std::size_t i = 0; i < v.size(); ++i)
      if (!ok(v[i])) fail(where + key + "[" + std::to_string(i) + "]", what, &v[i]);
    return v;
  }
  // Absent, or as `check` wants it.
  template <class Check>
  void optional(const nlohmann::json& obj, const std::string& key, Check check) const {
    if (obj.is_object() && obj.contains(key)) check();
  }
  const nlohmann::json& objects(const nlohmann::json& obj, const std::string& key, const std::string& where) const {
    const auto& v = at(obj, key, where + key);
    if (!v.is_array()) fail(where + key, "an array of objects", &v);
    for (std::size_t i = 0; i < v.size(); ++i)
      if (!v[i].is_object()) fail(where + key + "[" + std::to_string(i) + "]", "an object", &v[i]);
    return v;
  }
  // `check(entry, prefix)` for each object of the array `key`, the prefix naming it ("key[i].");
  // with `nonempty`, an empty array is refused (a summary over nothing would read as perfect).
  template <class Check>
  void each(const nlohmann::json& obj, const std::string& key, const std::string& where, Check check, bool nonempty = false) const {
    const auto& v = objects(obj, key, where);
    if (nonempty && v.empty()) fail(where + key, "a non-empty array of objects", &v);
    for (std::size_t i = 0; i < v.size(); ++i) check(v[i], where + key + "[" + std::to_string(i) + "].");
  }

private:
  std::string file_;
};


inline bool is_count(const nlohmann::json& v) { return v.is_number_integer() && v.get<long long>() > 0 && v.get<long long>() < 1000000000; }
inline bool is_number_or_null(const nlohmann::json& v) { return v.is_number() || v.is_null(); }
inline bool is_flag(const nlohmann::json& v) { return v.is_boolean(); }

}  // namespace scoleid::crosscheck
