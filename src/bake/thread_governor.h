#pragma once
// ThreadGovernor: the solver's team sized to the cores that other work leaves it (README,
// `--threads`; docs/benchmarks.md, "Threads"). libgomp's threads spin at each of a step's
// barriers, so a team member that waits for a core stalls the others: two bakes of two
// threads each on the same two cores stepped 10-140 times slower than one thread alone.
// Between frames the governor reads how long the team's threads waited for a core (the
// kernel's run delay, /proc/self/task/*/schedstat) beyond the CPU time of the bake's own
// helper threads (writers, the frame thread); when other work took more than a tenth of the
// team's time it steps on the threads that kept running; later it tries a thread more, and
// keeps it while no one waits. The bytes are the same for any thread count: no change of the
// team changes a file.
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace treeanim {

// What one window of frames measured.
struct TeamWindow {
  int threads = 1;           // the team's size during the window
  double seconds = 0;        // its wall time
  double team_wait = 0;      // s, the team's threads' summed run delay
  double helpers_cpu = 0;    // s, the CPU time of the process's other threads
};

// The governor's decisions, apart from the clock and /proc (unit-tested on made-up windows).
class TeamPolicy {
 public:
  // A window shorter than this is extended: its sums would be a few scheduler ticks.
  static constexpr double kWindowSeconds = 0.25;
  // Other work keeping the team waiting more than this share of its time shrinks the team: to
  // the threads that share leaves running, at most as many as there are cores, and by one at least.
  static constexpr double kShrinkShare = 0.10;
  // After a shrink (or a try that failed), the next try of a thread more waits this long,
  // doubled after each failed try up to kLongestWait.
  static constexpr double kFirstWait = 2, kLongestWait = 64;

  // What a window's end changed.
  enum class Change { kNone, kShrunk, kTrying, kTryFailed, kGrown };

  // `most`: the team it was given; `cores`: the CPUs the process may run on.
  TeamPolicy(int most, int cores) : most_(most), cores_(cores), threads_(most) {}
  // The window just ended => the team's size for the next (threads()).
  Change next(const TeamWindow& window);
  int threads() const { return threads_; }
  int most() const { return most_; }
  // The share of the team's time that other work kept it waiting in the last window.
  double last_share() const { return last_share_; }

 private:
  int most_, cores_, threads_;
  double wait_ = kFirstWait;  // s before the next try of a thread more
  double since_ = 0;          // s since the last change
  bool trying_ = false;       // the window that ended ran a thread more on trial
  double last_share_ = 0;
};

class ThreadGovernor {
 public:
  // `most`: the team the bake was given (omp_get_max_threads()); `tell`: takes the line that
  // says a change (BakeLog::team_resized). Does nothing for one thread, or where the kernel
  // keeps no schedstat.
  ThreadGovernor(int most, std::function<void(const std::string&)> tell);
  // The team it was given back (the next tree of a forest starts from it).
  ~ThreadGovernor();
  ThreadGovernor(const ThreadGovernor&) = delete;
  ThreadGovernor& operator=(const ThreadGovernor&) = delete;
  // After each frame, on the thread that starts the solver's parallel regions: at the end of
  // a window, the team resized for the next frames (omp_set_num_threads).
  void frame_done(long long frame);

 private:
  struct TaskTimes {
    double cpu = 0, wait = 0;  // s
  };
  std::map<long, TaskTimes> read_tasks() const;
  std::vector<long> team_tasks() const;

  TeamPolicy policy_;
  std::function<void(const std::string&)> tell_;
  bool active_;
  double window_start_ = 0;
  std::map<long, TaskTimes> last_;
};

}  // namespace treeanim
