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

// The signals a bake is interrupted by, each with its exit code and the line said when no
// output was open (a constant: the handler may only write).
struct Interrupt {
  int number;
  const char* name;
  int exit_code;
  const char* unopened;
};
#define TREEANIM_INTERRUPT(signal, code) \
  {signal, #signal, code, "treeanim: interrupted by " #signal " while no output was open; none was left half-written\n"}
constexpr Interrupt kInterrupts[] = {
    TREEANIM_INTERRUPT(SIGINT, kExitSigint),
    TREEANIM_INTERRUPT(SIGTERM, kExitSigterm),
    TREEANIM_INTERRUPT(SIGHUP, kExitSighup),
};
#undef TREEANIM_INTERRUPT

const Interrupt& find_interrupt(int signal_number) {
  for (const Interrupt& interrupt : kInterrupts)
    if (interrupt.number == signal_number) return interrupt;
  return kInterrupts[1];  // not reached: only these have the handler
}

// Only async-signal-safe calls here: write and _exit.
extern "C" void record_signal(int signal_number) {
  if (deferring.load() > 0) {
    received_signal.store(signal_number);
    return;
  }
  const Interrupt& interrupt = find_interrupt(signal_number);
  size_t length = 0;
  while (interrupt.unopened[length]) ++length;
  [[maybe_unused]] const ssize_t written = write(STDERR_FILENO, interrupt.unopened, length);
  _exit(interrupt.exit_code);
}

}  // namespace

void install_interrupt_handlers() {
  struct sigaction action {};
  action.sa_handler = record_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;
  for (const Interrupt& interrupt : kInterrupts) sigaction(interrupt.number, &action, nullptr);
  // A file-size limit (ulimit -f) must fail the write (EFBIG => exit 4, temporaries removed),
  // not kill the process with SIGXFSZ and strand the temporaries.
  std::signal(SIGXFSZ, SIG_IGN);
  // Nor a reader that closed its end of stdout or stderr (`| head`): the print fails, the bake goes on.
  std::signal(SIGPIPE, SIG_IGN);
}

int pending_signal() { return received_signal.load(); }

int interrupted_exit_code(int signal_number) { return find_interrupt(signal_number).exit_code; }

const char* interrupt_name(int signal_number) { return find_interrupt(signal_number).name; }

DeferredInterrupts::DeferredInterrupts() { deferring.fetch_add(1); }

// What the span printed reaches its pipe before a signal outside spans ends the process
// (_exit drops stdio's buffers): a forest's summaries of the trees it finished.
DeferredInterrupts::~DeferredInterrupts() {
  std::fflush(stdout);
  deferring.fetch_sub(1);
}

}  // namespace treeanim
