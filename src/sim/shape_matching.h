#pragma once
// Local shape matching (Müller et al. 2005; docs/solver.md, "Local shape matching"): clusters
// fitted four at a time, their rotations found in vector lanes, and the corrections toward
// their goals.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <span>

#include "sim/solver_step.h"

namespace treeanim {

// Clusters matched at once: one a lane of Double4 (extract_rotations).
constexpr size_t kMatchLanes = 4;

// Goals g = R q + t of cluster c (R column-major), with t given as t - t0 => per-membership
// corrections alpha_c (g - p) = alpha_c ((R q - q) + (t - t0) - u_p) in `corrections` (0 for
// a released membership).
template <typename Real>
void write_corrections(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                       const Rows3<Real>& predicted_offset, size_t c, const double (&R)[9], const double (&shift)[3],
                       Rows3<Real>& corrections);

// Up to kMatchLanes awake clusters; `pinned`: attached leaves, each fitted about its shared
// vertex held at its branch's goal (held_point), the branches matched already; else each about
// its centre => each fitted, its rotation warm-started from the state's and found in a lane
// (extract_rotations), the fit kept (rotation and shift in the state, R in the scratch) and its
// corrections written => the lowest cluster whose fit is not finite, kNone for none.
template <typename Real>
uint32_t match_in_lanes(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                        StepScratch<Real>& scratch, std::span<const uint32_t> clusters, bool pinned);

// Attached leaf c, its branch matched => the displacement from rest of its shared vertex at
// the branch's goal, where the leaf's fit holds it.
template <typename Real>
Eigen::Vector3d held_point(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                           const StepScratch<Real>& scratch, uint32_t c);

// Awake clusters added one by one => matched kMatchLanes at a time (match_in_lanes), each then
// sampling its air for the next step when `air` (a flying leaf samples it where its fit put it).
template <typename Real>
class MatchLanes {
 public:
  MatchLanes(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
             StepScratch<Real>& scratch, bool pinned, bool air)
      : model_(model), attachment_(attachment), state_(state), scratch_(scratch), pinned_(pinned), air_(air),
        lanes_air_(model, attachment, state, scratch) {}
  void add(uint32_t c) {
    clusters_[count_++] = c;
    if (count_ == kMatchLanes) flush();
  }
  // The clusters added since the last flush => matched.
  void flush() {
    if (count_ == 0) return;
    const std::span<const uint32_t> clusters(clusters_, count_);
    bad_ = std::min(bad_, match_in_lanes(model_, attachment_, state_, scratch_, clusters, pinned_));
    if (air_) {
      for (const uint32_t c : clusters) lanes_air_.add(c);
      lanes_air_.flush();
    }
    count_ = 0;
  }
  // The lowest cluster whose fit was not finite, kNone for none.
  uint32_t bad() const { return bad_; }

 private:
  const SolverModel<Real>& model_;
  const Attachment<Real>& attachment_;
  SimState& state_;
  StepScratch<Real>& scratch_;
  const bool pinned_, air_;
  AirLanes<Real> lanes_air_;
  uint32_t clusters_[kMatchLanes];
  size_t count_ = 0;
  uint32_t bad_ = kNone;
};

}  // namespace treeanim
