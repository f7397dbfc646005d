#include "scoleid/io/interrupt.h"

#include <csignal>
#include <cstring>
#include <string>

namespace scoleid::io {

namespace {
volatile std::sig_atomic_t g_signal = 0;
extern "C" void record_signal(int s) {
  if (g_signal == 0) g_signal = s;
}
}  // namespace

Interrupted::Interrupted(int s)
    : std::runtime_error(std::string("interrupted by ") + (s == SIGINT ? "SIGINT" : s == SIGTERM ? "SIGTERM" : "a signal") +
                         "; no output written"),
      signal_(s) {}

void install_interrupt_handlers() {
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = record_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: waitpid() and friends return EINTR
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  // A reader that goes away (`| head`) must not kill the run before its outputs are committed:
  // writes to the closed pipe fail with EPIPE instead, and the printed table is simply cut short.
  std::signal(SIGPIPE, SIG_IGN);
}

int interrupt_signal() { return static_cast<int>(g_signal); }

void check_interrupt() {
  if (const int s = interrupt_signal()) throw Interrupted(s);
}

void clear_interrupt() { g_signal = 0; }

void request_interrupt(int signal) {
  if (g_signal == 0) g_signal = signal;
}

}  // namespace scoleid::io
