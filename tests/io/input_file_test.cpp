// Reading input files (io/input_file.h) and interruptible third-party calls (io/interrupt.h): an
// endless device is cut at the limit; a key repeated in JSON or YAML is refused naming its path;
// a call that cannot check for a signal is abandoned within one polling interval of it.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <csignal>
#include <functional>
#include <string>
#include <thread>

#include "scoleid/io/error.h"
#include "scoleid/io/input_file.h"
#include "scoleid/io/interrupt.h"

using namespace scoleid::io;

namespace {
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(InputFile, AnEndlessDeviceIsCutAtTheLimitAndADirectoryIsNamed) {
  const std::string e = error_of([] { read_text_file("/dev/zero", "scenario file", std::size_t{1} << 20); });
  EXPECT_NE(e.find("scenario file '/dev/zero'"), std::string::npos) << e;
  EXPECT_NE(e.find("1 MiB"), std::string::npos) << e;
  EXPECT_NE(error_of([] { read_text_file("/tmp", "JSON file"); }).find("is a directory"), std::string::npos);
  EXPECT_NE(error_of([] { read_text_file("/nonexistent/x.yaml", "JSON file"); }).find("cannot be opened"), std::string::npos);
}

TEST(InputFile, ARepeatedJsonKeyIsRefusedWithItsPathAndDistinctKeysAreKept) {
  const std::string e = error_of([] {
    parse_json_text(R"({"a": 1, "columns": [{"name": "x"}, {"name": "y", "kind": 1, "kind": 2}]})", "JSON file 'f'");
  });
  EXPECT_NE(e.find("JSON file 'f'"), std::string::npos) << e;
  EXPECT_NE(e.find("key 'columns[].kind' appears more than once"), std::string::npos) << e;
  EXPECT_NE(error_of([] { parse_json_text(R"({"a": 1, "a": 2})", "s"); }).find("key 'a'"), std::string::npos);
  // The same key in sibling objects, and at different depths, is no repetition.
  const auto j = parse_json_text(R"({"a": {"a": 1}, "b": [{"a": 2}, {"a": 3}], "c": [[{"a": 4}]]})", "s");
  EXPECT_EQ(j["b"][1]["a"], 3);
  EXPECT_EQ(j["c"][0][0]["a"], 4);
  EXPECT_NE(error_of([] { parse_json_text("{\"a\": ", "s"); }).find("malformed JSON"), std::string::npos);
  // A number beyond double's range is an error of the file, not of the program.
  EXPECT_NE(error_of([] { parse_json_text("{\"a\": 1e666666}", "s"); }).find("malformed JSON"), std::string::npos);
}

TEST(InputFile, ARepeatedYamlKeyIsRefusedWithItsPath) {
  const YAML::Node n = YAML::Load("grid: {truth.segments: [10], truth.segments: [1000]}\n");
  const std::string e = error_of([&] { check_yaml_document(n, "campaign file 'c.yaml'", true); });
  EXPECT_NE(e.find("grid.truth.segments"), std::string::npos) << e;
  EXPECT_NE(e.find("appears more than once"), std::string::npos) << e;
  EXPECT_EQ(error_of([] { check_yaml_document(YAML::Load("a: ~\nb: {c: 1}\n"), "s", true); }), "");
  EXPECT_NE(error_of([] { check_yaml_document(YAML::Load("a: ~\n"), "s", false); }).find("has no value"), std::string::npos);
}

TEST(Interruptible, ACallThatCannotCheckIsAbandonedAtTheSignalAndOtherwiseAnswers) {
  install_interrupt_handlers();
  EXPECT_EQ(interruptible([] { return 42; }), 42);
  std::thread raiser([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    std::raise(SIGTERM);
  });
  const auto t0 = std::chrono::steady_clock::now();
  double waited = -1.0;
  try {
    interruptible([] {
      std::this_thread::sleep_for(std::chrono::seconds(3));
      return 0;
    });
    ADD_FAILURE() << "not interrupted";
  } catch (const Interrupted& e) {
    waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(e.exit_code(), 143);
  }
  raiser.join();
  clear_interrupt();
  EXPECT_GT(waited, 0.09);
  EXPECT_LT(waited, 0.5);
  // An exception of the call reaches the caller.
  EXPECT_THROW(interruptible([]() -> int { throw InputError("x"); }), InputError);
}

// Nesting deeper than any file of ours is refused before anything recurses over it (a JSON of
// 100 000 nested arrays crashed the serializer of an error message).
TEST(InputFile, DeepNestingIsRefusedInJsonAndYaml) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  EXPECT_EQ(error_of([&] { parse_json_text(deep, "f.json"); }), "f.json: nested deeper than 100 levels");
  const std::string ok = std::string(50, '[') + std::string(50, ']');
  EXPECT_EQ(error_of([&] { parse_json_text(ok, "f.json"); }), "");
  EXPECT_EQ(error_of([&] { check_yaml_nesting("name: x\nbeam: " + deep, "f.yaml"); }), "f.yaml: line 2: nested deeper than 100 levels");
  // Brackets inside quotes and comments are text.
  EXPECT_EQ(error_of([&] { check_yaml_nesting("a: '" + deep.substr(0, 200) + "' # " + deep.substr(0, 300), "f.yaml"); }), "");
}
