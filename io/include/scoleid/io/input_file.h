#pragma once
// Reading the files the programs are given, before anything in them is used: one place that
// bounds the read and checks the document's shape common to every format (docs/theory.md §10).
//
// - read_text_file reads a file whole, at most max_bytes: a directory, a file that cannot be
//   opened and a longer file or device (/dev/zero, a runaway log) are refused with one InputError
//   line naming the file. Opening a FIFO blocks until a writer comes; a SIGINT/SIGTERM received
//   meanwhile ends the program as an interruption (io::Interrupted), not as a bad file.
// - parse_json_text parses JSON and refuses a key repeated within one object (nlohmann keeps the
//   last, so the first value would be dropped silently), naming the key's path.
// - JSON and flow YAML nested deeper than kMaxNesting levels are refused before anything recurses.
// - check_yaml_document refuses, in a parsed YAML document, a repeated key (yaml-cpp answers
//   node[key] with the first pair, dropping the later one silently), a non-scalar key, a scalar or
//   key that is not UTF-8 and (unless allow_null) a key written without a value; each alias's
//   target is visited once.
#include <cstddef>
#include <istream>
#include <streambuf>
#include <string>

#include <nlohmann/json.hpp>

namespace YAML {
class Node;
}

namespace scoleid::io {

// A file opened for reading whose reads a signal can end: std::ifstream retries a read that a
// signal interrupts (EINTR), so a read blocked on a FIFO whose writer stalls would never see
// SIGTERM. Here open() and read() returning EINTR call check_interrupt() (which throws
// io::Interrupted when a SIGINT/SIGTERM arrived) and otherwise retry. A directory or a file that
// cannot be opened is an InputError "<where>: is a directory" / "<where>: cannot be opened"
// (`where` names the file: "data file 'x.csv'").
class InputFileStream : public std::istream {
public:
  InputFileStream(const std::string& path, const std::string& where);
  ~InputFileStream() override;
  InputFileStream(const InputFileStream&) = delete;
  InputFileStream& operator=(const InputFileStream&) = delete;

private:
  struct Buf : std::streambuf {
    int fd = -1;
    char data[1 << 16];
    int_type underflow() override;
  } buf_;
};

// Input files larger than this are refused (scenarios, experiments, campaigns, suite families,
// modal data, truth.json and the cross-check's own JSON; data records are bounded by their sample
// count instead).
inline constexpr std::size_t kMaxInputFileBytes = std::size_t{256} << 20;
// JSON and YAML nested deeper than this are refused (no file of ours goes beyond 10 levels; a
// nesting of 100 000 would exhaust the stack of code that recurses over the document).
inline constexpr int kMaxNesting = 100;

// `what` names the kind of file in the message ("scenario file", "JSON file").
std::string read_text_file(const std::string& path, const std::string& what,
                           std::size_t max_bytes = kMaxInputFileBytes);
// The first `bytes` bytes of a regular file ("" for anything else: a FIFO is not read to sniff it).
std::string file_head(const std::string& path, std::size_t bytes);
nlohmann::json parse_json_text(const std::string& text, const std::string& source);
void check_yaml_document(const YAML::Node& root, const std::string& source, bool allow_null = false);
// Before YAML is parsed: flow collections ([ ], { }) nested deeper than kMaxNesting are refused
// with one line naming the line (the parser's own guard answers "bad file").
void check_yaml_nesting(const std::string& text, const std::string& source);

}  // namespace scoleid::io
