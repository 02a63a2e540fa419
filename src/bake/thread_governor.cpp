#include "bake/thread_governor.h"

#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <utility>

namespace treeanim {

TeamPolicy::Change TeamPolicy::next(const TeamWindow& window) {
  // The bake's own helpers may have taken the cores the team waited for: only the wait beyond
  // their CPU time is other work's.
  const double others = std::max(0.0, window.team_wait - window.helpers_cpu);
  last_share_ = window.seconds > 0 ? others / (window.threads * window.seconds) : 0;
  since_ += window.seconds;
  const bool crowded = last_share_ > kShrinkShare;
  if (trying_) {
    trying_ = false, since_ = 0;
    if (crowded) {
      --threads_;
      wait_ = std::min(2 * wait_, kLongestWait);
      return Change::kTryFailed;
    }
    wait_ = kFirstWait;
    return Change::kGrown;
  }
  if (crowded && threads_ > 1) {
    const int running = int(std::lround(threads_ * (1 - last_share_)));
    threads_ = std::max(1, std::min({threads_ - 1, cores_, running}));
    wait_ = kFirstWait, since_ = 0;
    return Change::kShrunk;
  }
  if (!crowded && threads_ < most_ && since_ >= wait_) {
    ++threads_;
    trying_ = true, since_ = 0;
    return Change::kTrying;
  }
  return Change::kNone;
}

namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

ThreadGovernor::ThreadGovernor(int most, std::function<void(const std::string&)> tell)
    : policy_(most, omp_get_num_procs()), tell_(std::move(tell)) {
  last_ = read_tasks();
  active_ = most > 1 && !last_.empty();
  window_start_ = now_seconds();
}

ThreadGovernor::~ThreadGovernor() {
  if (policy_.threads() != policy_.most()) omp_set_num_threads(policy_.most());
}

// Each thread of the process => its CPU time and run delay (schedstat: ns on a CPU, ns
// runnable and waiting for one, time slices); empty where the kernel keeps none.
std::map<long, ThreadGovernor::TaskTimes> ThreadGovernor::read_tasks() const {
  std::map<long, TaskTimes> tasks;
  try {
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task", error)) {
      std::ifstream in(entry.path() / "schedstat");
      double cpu = 0, wait = 0;
      if (!(in >> cpu >> wait)) continue;  // the thread ended meanwhile
      tasks[std::strtol(entry.path().filename().c_str(), nullptr, 10)] = {cpu * 1e-9, wait * 1e-9};
    }
  } catch (const std::filesystem::filesystem_error&) {  // the listing failed midway: no window
    tasks.clear();
  }
  return tasks;
}

// The threads the solver's next parallel region runs on (libgomp keeps its pool's threads).
std::vector<long> ThreadGovernor::team_tasks() const {
  std::vector<long> team(size_t(omp_get_max_threads()), 0);
#pragma omp parallel
  team[size_t(omp_get_thread_num())] = long(gettid());
  return team;
}

void ThreadGovernor::frame_done(long long frame) {
  if (!active_) return;
  const double now = now_seconds();
  if (now - window_start_ < TeamPolicy::kWindowSeconds) return;
  const std::vector<long> team = team_tasks();
  std::map<long, TaskTimes> tasks = read_tasks();
  if (tasks.empty()) {  // /proc stopped answering: the team stays as it is
    active_ = false;
    return;
  }
  TeamWindow window{.threads = policy_.threads(), .seconds = now - window_start_};
  for (const auto& [id, times] : tasks) {
    const auto before = last_.find(id);
    if (before == last_.end()) continue;
    if (std::find(team.begin(), team.end(), id) != team.end())
      window.team_wait += times.wait - before->second.wait;
    else
      window.helpers_cpu += times.cpu - before->second.cpu;
  }
  const int was = policy_.threads();
  const TeamPolicy::Change change = policy_.next(window);
  if (policy_.threads() != was) omp_set_num_threads(policy_.threads());
  char line[256];
  if (change == TeamPolicy::Change::kShrunk) {
    std::snprintf(line, sizeof line,
                  "treeanim: frame %lld: the solver's %d threads waited for a core %.0f %% of the time (other work, or "
                  "more threads than cores): stepping on %d (the bytes are the same for any thread count)",
                  frame, was, 100 * policy_.last_share(), policy_.threads());
    tell_(line);
  }
  if (change == TeamPolicy::Change::kGrown) {
    std::snprintf(line, sizeof line, "treeanim: frame %lld: a core came free: stepping on %d threads", frame,
                  policy_.threads());
    tell_(line);
  }
  last_ = std::move(tasks);
  window_start_ = now;
}

}  // namespace treeanim
