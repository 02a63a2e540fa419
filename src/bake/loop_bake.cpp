#include "bake/loop_bake.h"

#include <algorithm>
#include <cmath>

#include "bake/signals.h"

namespace treeanim {

namespace {

// The state's positions as the outputs see them (float).
std::vector<float> positions_of(const SimState& state) {
  return std::vector<float>(state.positions.data(), state.positions.data() + state.positions.size());
}

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + long(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

double rms_distance(const float* a, const float* b, size_t values) {
  double sum = 0;
  for (size_t i = 0; i < values; ++i) sum += double(a[i] - b[i]) * double(a[i] - b[i]);
  return values ? std::sqrt(sum / double(values / 3)) : 0.0;
}

LoopWarmup warm_up_loop(Simulator& simulator, SimState& state, long long first, long long frames, std::FILE* log,
                        ThreadGovernor& governor) {
  LoopWarmup warmup;
  std::vector<float> boundary = positions_of(state);
  while (warmup.periods < kMaxLoopWarmupPeriods) {
    SeamMeter period;
    period.add(boundary);
    for (long long k = 1; k <= frames; ++k) {
      // Interrupted: the frame loop that follows stops at once and removes the outputs.
      if (pending_signal()) return warmup;
      simulator.advance_frame(state, first + k);
      governor.frame_done(first + k);
      period.add(positions_of(state));
    }
    ++warmup.periods;
    const std::vector<float> next = positions_of(state);
    const double step = period.median_step();
    const double change = rms_distance(next.data(), boundary.data(), next.size());
    warmup.change = step > 0 ? change / step : (change > 0 ? INFINITY : 0.0);
    boundary = next;
    if (log)
      std::fprintf(log, "treeanim: loop warm-up period %d: the state changed by %.3g of the median frame step\n",
                   warmup.periods, warmup.change);
    if (warmup.change <= kLoopRepeatChange) {
      warmup.converged = true;
      break;
    }
  }
  return warmup;
}

void SeamMeter::add(const std::vector<float>& positions) {
  if (first_.empty()) first_ = positions;
  else steps_.push_back(rms_distance(positions.data(), previous_.data(), positions.size()));
  previous_ = positions;
}

double SeamMeter::seam() const { return rms_distance(first_.data(), previous_.data(), first_.size()); }

double SeamMeter::median_step() const { return median(steps_); }

}  // namespace treeanim
