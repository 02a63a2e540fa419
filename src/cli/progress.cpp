#include "cli/progress.h"

#include <unistd.h>

#include <algorithm>
#include <string>

namespace treeanim {

namespace {

std::string format_duration(double seconds) {
  const long long s = static_cast<long long>(seconds + 0.5);
  char text[32];
  if (s >= 3600)
    std::snprintf(text, sizeof text, "%lldh%02lldm", s / 3600, (s / 60) % 60);
  else if (s >= 60)
    std::snprintf(text, sizeof text, "%lldm%02llds", s / 60, s % 60);
  else
    std::snprintf(text, sizeof text, "%llds", s);
  return text;
}

}  // namespace

Progress::Progress(long long total, Verbosity verbosity, std::FILE* out)
    : total_(std::max(1LL, total)),
      out_(out),
      enabled_(verbosity != Verbosity::kQuiet),
      terminal_(isatty(fileno(out)) != 0),
      start_(std::chrono::steady_clock::now()) {}

double Progress::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::update(long long done) {
  if (!enabled_) return;
  const double seconds = elapsed();
  const double rate = seconds > 0 ? done / seconds : 0;
  const double eta = rate > 0 ? (total_ - done) / rate : 0;
  const int percent = static_cast<int>(100 * done / total_);
  if (terminal_) {
    // Redraw at most 10 times a second: a fast bake must not spend its time printing.
    if (done < total_ && seconds - last_draw_ < 0.1) return;
    last_draw_ = seconds;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(kWidth * done / total_);
    std::string bar(filled, '#');
    bar.resize(kWidth, '-');
    std::fprintf(out_, "\r[%s] %3d%% %lld/%lld frames  %.1f frames/s  ETA %s   ", bar.c_str(),
                 percent, done, total_, rate, format_duration(eta).c_str());
  } else {
    const int step = percent / 5;
    if (step == last_percent_step_) return;
    last_percent_step_ = step;
    std::fprintf(out_, "progress: %3d%% (%lld/%lld frames, %.1f frames/s, ETA %s)\n", percent, done,
                 total_, rate, format_duration(eta).c_str());
  }
  std::fflush(out_);
}

void Progress::finish() {
  if (enabled_ && terminal_) std::fprintf(out_, "\n");
}

void Progress::note(const std::string& line) {
  if (!enabled_) return;
  if (terminal_) {
    std::fprintf(out_, "\r\033[K");  // the bar's line cleared
    last_draw_ = -1;                 // and drawn again at the next update
  }
  std::fprintf(out_, "%s\n", line.c_str());
  std::fflush(out_);
}

bool LongTaskProgress::due(bool starts) {
  if (!enabled_) return false;
  const auto now = std::chrono::steady_clock::now();
  if (starts) next_ = now + std::chrono::seconds(2);
  if (now < next_) return false;
  next_ = now + std::chrono::seconds(5);
  return true;
}

void LongTaskProgress::grown(int step, int steps, size_t modules) {
  if (!due(step == 1)) return;
  std::fprintf(out_, "growing: step %d of %d, %zu modules\n", step, steps, modules);
  std::fflush(out_);
}

void LongTaskProgress::trees(const char* what, size_t done, size_t total) {
  if (!due(done == 1)) return;
  std::fprintf(out_, "forest: %s, tree %zu of %zu\n", what, done, total);
  std::fflush(out_);
}

}  // namespace treeanim
