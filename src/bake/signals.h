#pragma once
// SIGINT / SIGTERM / SIGHUP (a closed terminal). While a bake holds files it must clean up
// (its outputs' locks, folders and temporaries, its journal and checkpoints: a
// DeferredInterrupts span), the handler only records the signal; the frame loop (run_frames)
// polls it between frames, aborts the outputs (removing temporaries) and the command exits
// 130 / 143 / 129, as it does for one that comes while the outputs are completed after the last
// frame (a skin's fit, a page); one that comes once they are in place leaves them (exit 0).
// Outside such a span nothing of the bake is half-written, so the signal ends the process at
// once with the same code: reading the scene and growing the tree (an L-system can take minutes
// to derive) stop as soon as asked.

namespace treeanim {

// Installs handlers for SIGINT, SIGTERM and SIGHUP and ignores SIGXFSZ and SIGPIPE (idempotent).
void install_interrupt_handlers();
// The signal number received since installation, or 0.
int pending_signal();
// A handled signal => the exit code of a command it interrupted (130, 143, 129), and its name.
int interrupted_exit_code(int signal_number);
const char* interrupt_name(int signal_number);

// While one lives, a signal is recorded for pending_signal() instead of ending the process.
class DeferredInterrupts {
 public:
  DeferredInterrupts();
  ~DeferredInterrupts();
  DeferredInterrupts(const DeferredInterrupts&) = delete;
  DeferredInterrupts& operator=(const DeferredInterrupts&) = delete;
};

}  // namespace treeanim
