#pragma once
// Progress of a bake on stderr: a redrawn bar with frames/s and ETA on a terminal, one line
// about every 5% in a log (not a TTY), nothing when quiet.
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>

namespace treeanim {

enum class Verbosity { kQuiet, kNormal, kVerbose };

class Progress {
 public:
  // total: frames the bake simulates; out: usually stderr.
  Progress(long long total, Verbosity verbosity, std::FILE* out);
  // Reports that `done` frames of `total` are complete.
  void update(long long done);
  // Ends the bar line (terminal) after the last update.
  void finish();
  // A line to tell while the bar runs: on a terminal the bar is cleared, the line printed and
  // the bar drawn again at the next update.
  void note(const std::string& line);

 private:
  double elapsed() const;
  long long total_;
  std::FILE* out_;
  bool enabled_;
  bool terminal_;
  int last_percent_step_ = 0;    // log mode: last 5% step printed (0%: nothing to say yet)
  double last_draw_ = -1;        // terminal mode: seconds at the last redraw
  std::chrono::steady_clock::time_point start_;
};

// Progress on stderr of a long task that draws no bar: a line once the task has run 2 s, then
// every 5 s; nothing when quiet, or for a task that ends sooner.
class LongTaskProgress {
 public:
  LongTaskProgress(Verbosity verbosity, std::FILE* out) : out_(out), enabled_(verbosity != Verbosity::kQuiet) {}
  // A derivation: step `step` of `steps` made `modules` modules ("growing: step S of N, M
  // modules"); step 1 starts a tree's clock.
  void grown(int step, int steps, size_t modules);
  // A pass over a forest's trees before the first is baked: `what` ("checking outputs") has
  // passed `done` of `total` trees ("forest: checking outputs, tree D of T"); 1 starts the clock.
  void trees(const char* what, size_t done, size_t total);

 private:
  bool due(bool starts);  // starts: the task's first call, which starts its clock

  std::FILE* out_;
  bool enabled_;
  std::chrono::steady_clock::time_point next_;  // when the next line is due
};

}  // namespace treeanim
