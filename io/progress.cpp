#include "scoleid/io/progress.h"

#include <cstdarg>
#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace scoleid::io {

namespace {

struct State {
  std::mutex mutex;
  ProgressSink::Line line;  // empty: stdout
  std::string pending;      // text of an unfinished line
};

State& state() {
  static State s;
  return s;
}

}  // namespace

void progress(const char* format, ...) {
  va_list args, copy;
  va_start(args, format);
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::vector<char> buf(static_cast<std::size_t>(n > 0 ? n : 0) + 1);
  std::vsnprintf(buf.data(), buf.size(), format, args);
  va_end(args);
  State& s = state();
  std::vector<std::string> lines;
  ProgressSink::Line sink;
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    if (!s.line) {
      std::fputs(buf.data(), stdout);
      return;
    }
    s.pending += buf.data();
    for (std::size_t nl; (nl = s.pending.find('\n')) != std::string::npos;) {
      lines.push_back(s.pending.substr(0, nl));
      s.pending.erase(0, nl + 1);
    }
    sink = s.line;
  }
  for (const auto& l : lines) sink(l);  // outside the lock: the sink may take its time
}

ProgressSink::ProgressSink(Line line) {
  State& s = state();
  std::lock_guard<std::mutex> lock(s.mutex);
  if (s.line) throw std::logic_error("ProgressSink: another sink is installed");
  s.line = std::move(line);
  s.pending.clear();
}

ProgressSink::~ProgressSink() {
  State& s = state();
  std::string rest;
  Line sink;
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    rest.swap(s.pending);
    sink.swap(s.line);
  }
  if (!rest.empty() && sink) {
    try {
      sink(rest);
    } catch (...) {  // a destructor does not throw; the line is lost
    }
  }
}

}  // namespace scoleid::io
