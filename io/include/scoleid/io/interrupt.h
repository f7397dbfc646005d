#pragma once
// SIGINT and SIGTERM end a run cleanly. The handler only records the signal; long loops (the
// truth's sample loop, the optimiser's iterations, a plotting child being waited for) call
// check_interrupt(), which throws Interrupted. The program's main catches it, its RunDirectory
// (run_directory.h) discards the staged outputs, and it exits 128 + signal (130 for SIGINT,
// 143 for SIGTERM): nothing half-written, nothing from the interrupted run left behind. (One
// exception, a whole run: scole-identify keeps the last iterate of an identification interrupted
// while it iterates, identify/run/identify_run.h RunOptions::keep_interrupted.)
#include <chrono>
#include <future>
#include <memory>
#include <stdexcept>
#include <thread>
#include <utility>

namespace scoleid::io {

class Interrupted : public std::runtime_error {
public:
  explicit Interrupted(int signal);
  int signal() const { return signal_; }
  int exit_code() const { return 128 + signal_; }

private:
  int signal_;
};

// Installs the recording handler for SIGINT and SIGTERM (without SA_RESTART, so a blocking wait
// returns EINTR), and ignores SIGPIPE: a program whose stdout reader has gone (`| head`) still
// finishes and commits its outputs, its further printing lost. Idempotent.
void install_interrupt_handlers();
// The signal received since installation, or 0.
int interrupt_signal();
// Throws Interrupted if a signal has been received.
void check_interrupt();
// Records a signal as if it had been received: the run under way ends at its next check (a
// caller's callback that must stop the run it is called from).
void request_interrupt(int signal);
// Forgets a received signal (a test that raised one; a caller that has dealt with it).
void clear_interrupt();

// A call that cannot check for a signal itself (a dense eigen solve inside Eigen, seconds to a
// minute for a fine chain) made interruptible: f runs on a worker thread while the caller waits,
// checking every 20 ms, and a signal throws Interrupted at once. The worker is then left to finish
// on its own and its result is dropped, so f must own everything it touches (capture by value).
// Exceptions of f reach the caller.
template <class F>
auto interruptible(F f) -> decltype(f()) {
  using R = decltype(f());
  auto task = std::make_shared<std::packaged_task<R()>>(std::move(f));
  std::future<R> result = task->get_future();
  std::thread([task] { (*task)(); }).detach();
  while (result.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready) check_interrupt();
  return result.get();
}

}  // namespace scoleid::io
