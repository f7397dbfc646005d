#pragma once
// Progress of a long run — the optimiser's iteration table, restarts, the fit test's message —
// as the run goes. By default it is printed on stdout (scole-identify --verbose); a caller that
// wants the lines elsewhere (the Python module hands them to a callback) installs a sink for the
// duration of a call. The sink is the process's: one at a time (a second is refused), and it
// receives whole lines without their '\n', from whichever thread prints them.
#include <functional>
#include <string>

namespace scoleid::io {

// printf-style; the text goes to the installed sink (split into lines), else to stdout.
void progress(const char* format, ...) __attribute__((format(printf, 1, 2)));

class ProgressSink {
public:
  using Line = std::function<void(const std::string&)>;
  explicit ProgressSink(Line line);  // std::logic_error when another sink is installed
  ~ProgressSink();                   // flushes an unfinished line, restores stdout
  ProgressSink(const ProgressSink&) = delete;
  ProgressSink& operator=(const ProgressSink&) = delete;
};

}  // namespace scoleid::io
