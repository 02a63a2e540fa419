#pragma once
// The two per-vertex kernels of a step, for a block of vertices (docs/solver.md, "One step"
// 5 and 1, and 3, "Wind and forces"): correct_block applies the mean correction of the matched step
// and measures the drag the next step will feel; predict_block predicts the next step:
// damping, gravity, the global pull toward the static deflection (Eq. 8) and the exact
// quadratic drag => v* and u_p = u + h v*. Loops without branches, vectorised across
// vertices; correction.cpp drives them.
#include <cmath>
#include <cstdint>

#include "sim/solver_model.h"

namespace treeanim {

// One block of a thread's vertices, on its stack (no allocation): 41 KB in float, 81 in
// double. Each block costs its goal writes' search for their run, splits of the runs and of
// the correction's air segments at its ends, and the flag checks: with 1,024 lanes the vertex
// passes take about 9 % less time than with 256 (docs/solver.md, "Costs").
constexpr int kVertexBlock = 1024;
// Where the kernels read a block's vertices, each array from the block's first: the mean
// correction of vertex k, its factors. Every value a kernel reads is 4 or 8
// bytes wide: a byte among them makes GCC vectorise the loop 16 lanes at a time, and its
// `omp simd` private arrays (16 lanes) then allow only 16-byte vectors for the whole loop.
template <typename Real>
struct VertexInputs {
  const Real* pull[3];
  const Real *drag, *half_damping, *kick_scale, *global;
  const Real* flying;   // 1 on a flying leaf, else 0
  const Real* goal[3];  // m: the offset from rest the global term pulls toward
  const Real* kicked;   // 1: the mean correction is a kick of the next step (a branch with the beam), 0: a projection now
};

template <typename Real>
struct VertexBlock {
  uint8_t moving[kVertexBlock];            // 1: the vertex steps; 0: anchored, asleep, no cluster
  Real pull[3][kVertexBlock];              // m, mean correction of its clusters, per axis
  // Per-step factors of each vertex; a vertex that does not move gets those of a still
  // point (no damping, drag, pull or fall), which map its u = 0, v = 0 onto themselves
  // exactly, so that the loops need no branch.
  Real drag[kVertexBlock];                 // 1/m, drag acceleration per (m/s)^2
  Real half_damping[kVertexBlock];         // velocity factor per half step
  Real kick_scale[kVertexBlock];           // Attachment::vertex_kick_scale
  Real global[kVertexBlock];               // global rate per step
  Real flying[kVertexBlock];               // 1 on a flying leaf
  Real kicked[kVertexBlock];               // SolverModel::vertex_shape_kick, as a factor
  Real check[kVertexBlock];                // sum of the new values: finite iff all are
  Real excess[kVertexBlock];               // m^2, > 0: ran farther than the runaway limit
};

// Exact quadratic drag over one step for constant air: du/dt = -k|u|u from u0 = air - v gives
// |u(h)| = |u0| / (1 + k|u0|h), so the velocity change u0 k|u0|h / (1 + k|u0|h) never
// overshoots the air velocity, whatever the wind speed or step. => that fraction of u0.
template <typename Real>
inline Real drag_share(Real drag, Real rx, Real ry, Real rz, Real step) {
  const Real kuh = drag * std::sqrt(rx * rx + ry * ry + rz * rz) * step;
  return kuh / (1 + kuh);
}

// Lane k of a block before its correction (u, v) => after it (Eq. 7: the mean correction p,
// now unless the step kicks it, v by p / h), and p. Both kernels call it: the correction pass
// keeps the results in memory only for the state (the last step), the prediction recomputes them.
template <typename Real>
struct CorrectedLane {
  Real ux, uy, uz, vx, vy, vz, px, py, pz, now;
};
template <typename Real>
inline CorrectedLane<Real> correct_lane(const VertexInputs<Real>& in, const Real* const offset[3],
                                        const Real* const velocity[3], int k, Real inv_h) {
  const Real now = Real(1) - in.kicked[k];
  const Real px = in.pull[0][k], py = in.pull[1][k], pz = in.pull[2][k];
  return {offset[0][k] + px * now,         offset[1][k] + py * now,         offset[2][k] + pz * now,
          velocity[0][k] + px * now * inv_h, velocity[1][k] + py * now * inv_h, velocity[2][k] + pz * now * inv_h,
          px,                              py,                              pz,
          now};
}

// A corrected lane => u and v of vertex k in memory.
template <typename Real>
inline void store_lane(Real* const offset[3], Real* const velocity[3], int k, const CorrectedLane<Real>& lane) {
  offset[0][k] = lane.ux, offset[1][k] = lane.uy, offset[2][k] = lane.uz;
  velocity[0][k] = lane.vx, velocity[1][k] = lane.vy, velocity[2][k] = lane.vz;
}

// Block of n lanes => true when some moving lane turned non-finite or ran away; the caller
// finds which. Kept out of the kernels' loops: a reduction there stops GCC from vectorising
// them. The order of the sum decides nothing.
template <typename Real>
inline bool block_flagged(const VertexBlock<Real>& block, int n) {
  Real total = 0, worst = 0;
#pragma omp simd reduction(+ : total) reduction(max : worst)
  for (int k = 0; k < n; ++k) {
    total += block.check[k];
    worst = std::max(worst, block.excess[k]);
  }
  return !(total - total == 0) || worst > 0;
}

// The air a cluster's vertices feel and its R (column-major), in Real, as the drag reads them.
template <typename Real>
struct DragFrame {
  Real air[3], R[9];
};

// Cluster c's frame from the step's air (per axis) and R (9 x C, column-major, double).
template <typename Real>
inline DragFrame<Real> drag_frame(const Real* const air[3], const double* rotation, size_t c) {
  DragFrame<Real> f;
  for (int i = 0; i < 3; ++i) f.air[i] = air[i][c];
  for (int i = 0; i < 9; ++i) f.R[i] = static_cast<Real>(rotation[9 * c + i]);
  return f;
}

// Corrected lane k with its cluster's frame f => the drag it will feel over the next step
// (force, damped, drag_damping), as correct_block describes.
template <typename Real>
inline void store_drag_lane(const VertexInputs<Real>& in, const CorrectedLane<Real>& lane, const DragFrame<Real>& f,
                            int k, Real half_inv_h, const Real* compliance, const Real* mass, Real* const force[3],
                            Real* const damped[3], Real* drag_damping) {
  const auto [ux, uy, uz, vx, vy, vz, px, py, pz, now] = lane;
  // The drag at the step's start, from the velocity there: half a step of damping and of
  // the pull after the staggered v (second order; docs/solver.md "One step"). The pull is
  // toward the last goal without the part this vertex's velocity took off through its drag,
  // and that damping is implicit: the velocity is divided by 1 + gamma h / 2, gamma = K c
  // (docs/solver.md "Aerodynamic damping"): stable at any step, however strong the drag.
  const Real half = in.half_damping[k], pull_back = in.global[k] * half_inv_h, shape = (1 - now) * half_inv_h;
  const Real implicit = 1 / (1 + pull_back * compliance[k]);
  const Real wx = (vx * half - pull_back * (ux - (in.goal[0][k] + damped[0][k])) + shape * px) * implicit;
  const Real wy = (vy * half - pull_back * (uy - (in.goal[1][k] + damped[1][k])) + shape * py) * implicit;
  const Real wz = (vz * half - pull_back * (uz - (in.goal[2][k] + damped[2][k])) + shape * pz) * implicit;
  damped[0][k] = compliance[k] * wx, damped[1][k] = compliance[k] * wy, damped[2][k] = compliance[k] * wz;
  const Real rx = f.air[0] - wx, ry = f.air[1] - wy, rz = f.air[2] - wz;
  // The instantaneous drag: an attached vertex moves with its branch, not with the air, so
  // the free-flight average over the step (drag_share) would understate it ever more as
  // the step grows (a leaf in a gale at a 0.25 s step: 16x).
  const Real scale = in.drag[k] * std::sqrt(rx * rx + ry * ry + rz * rz) * mass[k];
  drag_damping[k] = scale;
  // The chain takes its moments with rest arms, so its load is the air's push and the
  // velocity's drag turned back into the cluster's rest frame, R^T w: with the arm it
  // moves with, a drag that opposes a limb's motion then always opposes it, however far
  // the limb has turned (in the world frame a limb past a quarter turn was pushed on).
  const Real bx = f.R[0] * wx + f.R[1] * wy + f.R[2] * wz;
  const Real by = f.R[3] * wx + f.R[4] * wy + f.R[5] * wz;
  const Real bz = f.R[6] * wx + f.R[7] * wy + f.R[8] * wz;
  force[0][k] = (f.air[0] - bx) * scale;
  force[1][k] = (f.air[1] - by) * scale;
  force[2][k] = (f.air[2] - bz) * scale;
}

// Predicted vertices [begin, begin + n) => with kForce, the drag each will feel over the next
// step from its velocity at the step's start after the correction (prediction.drag_force,
// damping_offset; scratch.vertex_drag_damping). The corrected u and v are written in place
// with kEnd (`prediction` then holds the state at the step's end, for the frame's state), and
// the runaway limit is checked; otherwise predict_block recomputes them, which saves a write
// of u and v per vertex, and only a flagged block is written (for the caller to find the
// vertex at fault). With SolverModel::lane_frames each lane reads its cluster's frame itself.
// Returns block_flagged.
template <bool kEnd, bool kForce, typename Real>
inline bool correct_block(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                          StepScratch<Real>& scratch, StepPrediction<Real>& prediction, size_t begin, int n,
                          const VertexInputs<Real>& in, VertexBlock<Real>& block) {
  const Real inv_h = static_cast<Real>(1.0 / model.h);
  const Real half_inv_h = static_cast<Real>(0.5 / model.h);
  const Real* air[3] = {scratch.cluster_air.col(0).data(), scratch.cluster_air.col(1).data(),
                        scratch.cluster_air.col(2).data()};
  Real *force[3] = {nullptr, nullptr, nullptr}, *damped[3] = {nullptr, nullptr, nullptr};
  if constexpr (kForce)
    for (int i = 0; i < 3; ++i) {
      force[i] = prediction.drag_force.col(i).data() + begin;
      damped[i] = prediction.damping_offset.col(i).data() + begin;
    }
  const Real* compliance = prediction.damping_compliance.data() + begin;
  Real* drag_damping = scratch.vertex_drag_damping.data() + begin;
  const double* rotation = scratch.cluster_rotation_matrix.data();
  const uint32_t* air_cluster = attachment.vertex_air_cluster.data() + begin;
  const Real* mass = model.vertex_mass.data() + begin;
  const Real limit2 = static_cast<Real>(model.runaway_distance2);
  Real* offset[3] = {prediction.offset.col(0).data() + begin, prediction.offset.col(1).data() + begin,
                     prediction.offset.col(2).data() + begin};
  Real* velocity[3] = {prediction.velocity.col(0).data() + begin, prediction.velocity.col(1).data() + begin,
                       prediction.velocity.col(2).data() + begin};
  auto check = [&](int k, const CorrectedLane<Real>& lane) {
    const auto [ux, uy, uz, vx, vy, vz, px, py, pz, now] = lane;
    block.check[k] = ((ux + vx) + (uy + vy)) + (uz + vz);
    Real excess = 0;  // > 0: an attached vertex ran away
    if constexpr (kEnd) excess = (1 - in.flying[k]) * (ux * ux + uy * uy + uz * uz) - limit2;
    block.excess[k] = excess;
  };
  if (!kForce || model.lane_frames) {
#pragma omp simd
    for (int k = 0; k < n; ++k) {
      const CorrectedLane<Real> lane = correct_lane(in, offset, velocity, k, inv_h);
      if constexpr (kEnd) store_lane(offset, velocity, k, lane);
      if constexpr (kForce)
        store_drag_lane(in, lane, drag_frame(air, rotation, air_cluster[k]), k, half_inv_h, compliance, mass, force,
                        damped, drag_damping);
      check(k, lane);
    }
  } else {
    // The block runs in segments of consecutive vertices that feel the air of one cluster and
    // turn with its R (most of a mesh cluster's vertices are consecutive): its twelve values
    // are read once per segment, not gathered per lane.
    for (int first = 0; first < n;) {
      const uint32_t c = air_cluster[first];
      int stop = first + 1;
      while (stop < n && air_cluster[stop] == c) ++stop;
      const DragFrame<Real> f = drag_frame(air, rotation, c);
#pragma omp simd
      for (int k = first; k < stop; ++k) {
        const CorrectedLane<Real> lane = correct_lane(in, offset, velocity, k, inv_h);
        if constexpr (kEnd) store_lane(offset, velocity, k, lane);
        store_drag_lane(in, lane, f, k, half_inv_h, compliance, mass, force, damped, drag_damping);
        check(k, lane);
      }
      first = stop;
    }
  }
  const bool flagged = block_flagged(block, n);
  if constexpr (!kEnd)
    if (flagged)
      for (int k = 0; k < n; ++k) store_lane(offset, velocity, k, correct_lane(in, offset, velocity, k, inv_h));
  return flagged;
}

// Corrected vertices [begin, begin + n) (kCorrect: vertices the correction pass left
// uncorrected, corrected here first, as it would have) => their prediction for the next step,
// in place, written for every lane (a still lane maps onto itself). `kick` is 1, or 1/2 when the
// velocities are not staggered (a step from the state: leapfrog's first half kick). The
// drag's square roots and divisions dominate the loop; kDrag false leaves them out where no
// lane feels its drag directly (an attached vertex with the beam feels it through its goal):
// the share is then +0 exactly as they would compute it. Returns block_flagged.
template <bool kCorrect, bool kDrag, typename Real>
inline bool predict_block(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                          const StepScratch<Real>& scratch, StepPrediction<Real>& prediction, size_t begin, int n,
                          const VertexInputs<Real>& in, Real kick, VertexBlock<Real>& block) {
  const double h = model.h;
  const Real inv_h = static_cast<Real>(1.0 / h) * kick, step = static_cast<Real>(h), half_step = static_cast<Real>(h / 2);
  // The drag moves an attached vertex itself only without the beam (no global term); with
  // it, the drag acts through the goal. A flying leaf always feels it.
  const Real direct = model.beam ? Real(0) : Real(1);
  // The global term: a kick toward the goal with the beam, else a projection of the prediction.
  const Real kicked = model.kick ? Real(1) : Real(0), projected = Real(1) - kicked;
  const Real inv_step = static_cast<Real>(1.0 / h);  // also the correction's, as correct_block's inv_h
  const Eigen::Vector3d& gravity = model.options.gravity;
  const Real gravity_step[3] = {static_cast<Real>(gravity.x() * h) * kick, static_cast<Real>(gravity.y() * h) * kick,
                                static_cast<Real>(gravity.z() * h) * kick};
  const Real* air[3] = {scratch.cluster_air.col(0).data(), scratch.cluster_air.col(1).data(),
                        scratch.cluster_air.col(2).data()};
  const uint32_t* air_cluster = attachment.vertex_air_cluster.data() + begin;
  Real* offset[3] = {prediction.offset.col(0).data() + begin, prediction.offset.col(1).data() + begin,
                     prediction.offset.col(2).data() + begin};
  Real* velocity[3] = {prediction.velocity.col(0).data() + begin, prediction.velocity.col(1).data() + begin,
                       prediction.velocity.col(2).data() + begin};
#pragma omp simd
  for (int k = 0; k < n; ++k) {
    const uint32_t c = air_cluster[k];
    Real ux = offset[0][k], uy = offset[1][k], uz = offset[2][k];
    Real vx = velocity[0][k], vy = velocity[1][k], vz = velocity[2][k];
    if constexpr (kCorrect) {
      const CorrectedLane<Real> lane = correct_lane(in, offset, velocity, k, inv_step);
      ux = lane.ux, uy = lane.uy, uz = lane.uz, vx = lane.vx, vy = lane.vy, vz = lane.vz;
    }
    const Real ax = air[0][c], ay = air[1][c], az = air[2][c];
    // A symmetric (Strang) splitting of the step's velocity change about the kick of the
    // corrected position: half the damping, half the drag, the kick (gravity on a flying leaf,
    // with the beam the global pull toward the goal on an attached vertex), half the drag,
    // half the damping. Each half is exact for its own term, so the whole is second order in
    // h and never overshoots (docs/solver.md, "One step"); the kick, scaled by sinh(x) / x,
    // then moves as a steady force moves a damped vertex over the step, however strong the
    // damping (an overdamped limb crept 1 / 40 as fast as it should at zeta 10).
    const Real half = in.half_damping[k], falling = in.flying[k], scale = in.kick_scale[k];
    const Real pull_back = in.global[k] * inv_h * kicked * scale, drag = in.drag[k] * std::max(direct, falling);
    vx *= half, vy *= half, vz *= half;
    Real share = kDrag ? drag_share(drag, ax - vx, ay - vy, az - vz, half_step) : Real(0);
    vx += (ax - vx) * share, vy += (ay - vy) * share, vz += (az - vz) * share;
    const Real shape = in.kicked[k] * inv_h * scale;
    vx += falling * gravity_step[0] - pull_back * (ux - in.goal[0][k]) + shape * in.pull[0][k];
    vy += falling * gravity_step[1] - pull_back * (uy - in.goal[1][k]) + shape * in.pull[1][k];
    vz += falling * gravity_step[2] - pull_back * (uz - in.goal[2][k]) + shape * in.pull[2][k];
    if constexpr (kDrag) share = drag_share(drag, ax - vx, ay - vy, az - vz, half_step);
    vx = (vx + (ax - vx) * share) * half, vy = (vy + (ay - vy) * share) * half, vz = (vz + (az - vz) * share) * half;
    Real px = ux + step * vx, py = uy + step * vy, pz = uz + step * vz;
    // With per_step stiffness, Eq. 8 as the paper writes it: the global rate moves the
    // predicted position toward its goal, a projection that no wind or step can overshoot.
    const Real project = in.global[k] * projected;
    const Real ex = project * (in.goal[0][k] - px), ey = project * (in.goal[1][k] - py), ez = project * (in.goal[2][k] - pz);
    px += ex, py += ey, pz += ez;
    vx += ex * inv_step, vy += ey * inv_step, vz += ez * inv_step;
    velocity[0][k] = vx, velocity[1][k] = vy, velocity[2][k] = vz;
    offset[0][k] = px, offset[1][k] = py, offset[2][k] = pz;
    block.check[k] = ((px + vx) + (py + vy)) + (pz + vz);
    block.excess[k] = 0;
  }
  return block_flagged(block, n);
}

}  // namespace treeanim
