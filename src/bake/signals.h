#pragma once
// SIGINT / SIGTERM during a bake: the handler only records the signal; the frame loop
// (run_frames) polls it between frames, aborts the outputs (removing temporaries) and the
// command exits 130 / 143.

namespace treeanim {

// Installs handlers for SIGINT and SIGTERM and ignores SIGXFSZ (idempotent).
void install_interrupt_handlers();
// The signal number received since installation, or 0.
int pending_signal();

}  // namespace treeanim
