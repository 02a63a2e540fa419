#include "bake/signals.h"

#include <csignal>

namespace treeanim {

namespace {

volatile std::sig_atomic_t received_signal = 0;

extern "C" void record_signal(int signal_number) { received_signal = signal_number; }

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
}

int pending_signal() { return received_signal; }

}  // namespace treeanim
