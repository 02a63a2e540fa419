#include "bake/signals.h"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>

#include "common/errors.h"

namespace treeanim {

namespace {

// Lock-free atomics: the handler may run on any thread (an OpenMP worker too) and touch them.
std::atomic<int> received_signal{0};
std::atomic<int> deferring{0};  // spans alive (DeferredInterrupts)
static_assert(std::atomic<int>::is_always_lock_free);

// Only async-signal-safe calls here: write and _exit.
extern "C" void record_signal(int signal_number) {
  if (deferring.load() > 0) {
    received_signal.store(signal_number);
    return;
  }
  static constexpr char kSigint[] =
      "treeanim: interrupted by SIGINT while no output was open; none was left half-written\n";
  static constexpr char kSigterm[] =
      "treeanim: interrupted by SIGTERM while no output was open; none was left half-written\n";
  const bool sigint = signal_number == SIGINT;
  [[maybe_unused]] const ssize_t written =
      write(STDERR_FILENO, sigint ? kSigint : kSigterm, sigint ? sizeof kSigint - 1 : sizeof kSigterm - 1);
  _exit(interrupted_exit_code(signal_number));
}

}  // namespace

void install_interrupt_handlers() {
  struct sigaction action {};
  action.sa_handler = record_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  // A file-size limit (ulimit -f) must fail the write (EFBIG => exit 4, temporaries removed),
  // not kill the process with SIGXFSZ and strand the temporaries.
  std::signal(SIGXFSZ, SIG_IGN);
  // Nor a reader that closed its end of stdout or stderr (`| head`): the print fails, the bake goes on.
  std::signal(SIGPIPE, SIG_IGN);
}

int pending_signal() { return received_signal.load(); }

int interrupted_exit_code(int signal_number) { return signal_number == SIGINT ? kExitSigint : kExitSigterm; }

DeferredInterrupts::DeferredInterrupts() { deferring.fetch_add(1); }

// What the span printed reaches its pipe before a signal outside spans ends the process
// (_exit drops stdio's buffers): a forest's summaries of the trees it finished.
DeferredInterrupts::~DeferredInterrupts() {
  std::fflush(stdout);
  deferring.fetch_sub(1);
}

}  // namespace treeanim
