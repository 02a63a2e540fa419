#pragma once
// Seamless loops (time.loop, docs/scene.md): the wind is periodic over the bake (scene/), the
// tree runs whole periods until its motion repeats, and the baked frames are one period, so the
// last frame flows into the first.
#include <cstdio>
#include <vector>

#include "bake/thread_governor.h"
#include "sim/simulator.h"

namespace treeanim {

// Periods a loop may warm up before it is baked as it stands (a lightly damped tree settles in
// a few; a tree that never repeats is baked anyway and its seam reported).
constexpr int kMaxLoopWarmupPeriods = 32;

// A loop repeats when a period changes the state by at most this fraction of the median frame
// step (RMS over vertices): the seam is then a frame step within 10 %.
constexpr double kLoopRepeatChange = 0.1;

struct LoopWarmup {
  int periods = 0;        // whole periods run before the baked one
  double change = 0;      // RMS change of the state over the last period, / the median frame step
  bool converged = false; // change at most kLoopRepeatChange
};

// Runs `frames`-frame periods from `state` (at the loop's first frame `first`) until a period
// changes the state by at most kLoopRepeatChange, at most kMaxLoopWarmupPeriods. Notes each
// period on `log`, and each frame to `governor`. Returns as soon as a signal is pending (bake/signals.h).
LoopWarmup warm_up_loop(Simulator& simulator, SimState& state, long long first, long long frames, std::FILE* log,
                        ThreadGovernor& governor);

// The seam of a baked loop: the step from its last frame back to its first, against the median
// step between neighbouring frames (both RMS over vertices).
class SeamMeter {
 public:
  void add(const std::vector<float>& positions);  // the frames in order
  double seam() const;         // m
  double median_step() const;  // m

 private:
  std::vector<float> first_, previous_;
  std::vector<double> steps_;  // m, RMS step to each frame from the one before
};

// RMS over vertices of the distance between two (V*3) position sets.
double rms_distance(const float* a, const float* b, size_t values);

}  // namespace treeanim
