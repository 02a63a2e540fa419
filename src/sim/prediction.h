#pragma once
// The prediction of one step for a block of vertices (docs/solver.md, "One step" 1 and
// "Wind and forces"): corrected u and v => damping, gravity, the global pull back to rest
// (Eq. 8, -k u / h) and the exact quadratic drag => v* and u_p = u + h v*. One loop without
// branches, vectorised across vertices; correction.cpp drives it.
#include <array>
#include <cmath>
#include <cstdint>

#include "sim/solver_model.h"

namespace treeanim {

// One block of a thread's vertices, on its stack (no allocation).
constexpr int kVertexBlock = 256;
// 0, 1, ..., kVertexBlock - 1: a block's own lanes as rows.
inline const std::array<uint32_t, kVertexBlock> kLaneIndex = [] {
  std::array<uint32_t, kVertexBlock> lanes{};
  for (int k = 0; k < kVertexBlock; ++k) lanes[k] = static_cast<uint32_t>(k);
  return lanes;
}();

// Where predict_block reads a block's vertices: the mean correction of vertex k is row
// pull_row[k] of `pull`; the factors are per vertex.
template <typename Real>
struct VertexInputs {
  const Real* pull[3];
  const uint32_t* pull_row;
  const Real *drag, *damping, *global;
  const uint8_t* flying;
};

template <typename Real>
struct VertexBlock {
  uint8_t moving[kVertexBlock];            // 1: the vertex steps; 0: anchored, asleep, no cluster
  Real pull[3][kVertexBlock];              // m, mean correction of its clusters, per axis
  // Per-step factors of each vertex; a vertex that does not move gets those of a still
  // point (damping 1, no drag, no pull, no fall), which map its u = 0, v = 0 onto themselves
  // exactly, so that the loop needs no branch.
  Real drag[kVertexBlock];                 // 1/m, drag acceleration per (m/s)^2
  Real damping[kVertexBlock];              // velocity factor
  Real global[kVertexBlock];               // global rate per step
  uint8_t flying[kVertexBlock];            // 1 on a flying leaf
  Real end_offset[3][kVertexBlock];        // m, corrected u at the end of a frame (kEnd)
  Real end_velocity[3][kVertexBlock];      // m/s, corrected v at the end of a frame (kEnd)
  Real check[kVertexBlock];                // sum of the new values: finite iff all are
  Real excess[kVertexBlock];               // m^2, > 0: ran farther than the runaway limit
};

// Corrected vertices [begin, begin + n) => their prediction for the next step in
// `prediction`, written for every lane (a still lane maps onto itself); with `kEnd` also the
// corrected u and v in block.end_*. The drag's square root and division dominate the loop.
// Returns true when some moving vertex turned non-finite or (kEnd) ran away; the caller
// finds which.
template <bool kEnd, bool kDetach, typename Real>
inline bool predict_block(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                          const StepScratch<Real>& scratch, StepPrediction<Real>& prediction, size_t begin, int n,
                          const VertexInputs<Real>& in, VertexBlock<Real>& block) {
  const double h = model.h;
  const Real inv_h = static_cast<Real>(1.0 / h), step = static_cast<Real>(h);
  const Eigen::Vector3d& gravity = model.options.gravity;
  const Real gravity_step[3] = {static_cast<Real>(gravity.x() * h), static_cast<Real>(gravity.y() * h),
                                static_cast<Real>(gravity.z() * h)};
  const Real* air[3] = {scratch.cluster_air.col(0).data(), scratch.cluster_air.col(1).data(),
                        scratch.cluster_air.col(2).data()};
  Real* force[3] = {nullptr, nullptr, nullptr};
  if constexpr (kDetach)
    for (int i = 0; i < 3; ++i) force[i] = prediction.drag_force.col(i).data() + begin;
  const uint32_t* air_cluster = attachment.vertex_air_cluster.data() + begin;
  const double* mass = model.tree.vertex_mass.data() + begin;
  const Real limit2 = static_cast<Real>(model.runaway_distance2);
  Real *offset_x = prediction.offset.col(0).data() + begin, *offset_y = prediction.offset.col(1).data() + begin,
       *offset_z = prediction.offset.col(2).data() + begin;
  Real *velocity_x = prediction.velocity.col(0).data() + begin, *velocity_y = prediction.velocity.col(1).data() + begin,
       *velocity_z = prediction.velocity.col(2).data() + begin;
#pragma omp simd
  for (int k = 0; k < n; ++k) {
    const uint32_t c = air_cluster[k], row = in.pull_row[k];
    const Real px = in.pull[0][row], py = in.pull[1][row], pz = in.pull[2][row];
    const Real ux = offset_x[k] + px, uy = offset_y[k] + py, uz = offset_z[k] + pz;
    const Real vx = velocity_x[k] + px * inv_h, vy = velocity_y[k] + py * inv_h, vz = velocity_z[k] + pz * inv_h;
    // A flying leaf falls (its global rate is 0); an attached vertex is pulled back. These
    // impulses first, then the quadratic drag integrated exactly over the step for constant
    // air velocity from the velocity they left: du/dt = -k|u|u gives |u(h)| = |u0| / (1 + k|u0|h),
    // so the change never overshoots the air velocity, whatever the wind speed or step. In
    // this order the drag damps the whole step (docs/solver.md, "Wind and forces").
    const Real damping = in.damping[k], falling = static_cast<Real>(in.flying[k]), pull_back = in.global[k] * inv_h;
    const Real fx = (vx * damping + falling * gravity_step[0]) - pull_back * ux;
    const Real fy = (vy * damping + falling * gravity_step[1]) - pull_back * uy;
    const Real fz = (vz * damping + falling * gravity_step[2]) - pull_back * uz;
    const Real rx = air[0][c] - fx, ry = air[1][c] - fy, rz = air[2][c] - fz;
    const Real kuh = in.drag[k] * std::sqrt(rx * rx + ry * ry + rz * rz) * step;
    const Real share = kuh / (1 + kuh);
    const Real nx = fx + rx * share, ny = fy + ry * share, nz = fz + rz * share;
    const Real ax = ux + step * nx, ay = uy + step * ny, az = uz + step * nz;
    velocity_x[k] = nx;
    velocity_y[k] = ny;
    velocity_z[k] = nz;
    offset_x[k] = ax;
    offset_y[k] = ay;
    offset_z[k] = az;
    if constexpr (kDetach) {
      const Real scale = static_cast<Real>(mass[k]) * inv_h;
      force[0][k] = rx * share * scale;
      force[1][k] = ry * share * scale;
      force[2][k] = rz * share * scale;
    }
    Real sum = ((ax + nx) + (ay + ny)) + (az + nz);
    Real excess = 0;  // > 0: an attached vertex ran away (kEnd)
    if constexpr (kEnd) {
      block.end_offset[0][k] = ux;
      block.end_offset[1][k] = uy;
      block.end_offset[2][k] = uz;
      block.end_velocity[0][k] = vx;
      block.end_velocity[1][k] = vy;
      block.end_velocity[2][k] = vz;
      sum += (vx + vy) + vz;
      excess = (1 - falling) * (ux * ux + uy * uy + uz * uz) - limit2;
    }
    block.check[k] = sum;
    block.excess[k] = excess;
  }
  // One test for the block: a sum of finite values is finite (it only overflows far past any
  // tree, and then the caller's rescan finds nothing). Kept out of the loop above: a
  // reduction there stops GCC from vectorising it. The order of the sum decides nothing.
  Real total = 0, worst = 0;
#pragma omp simd reduction(+ : total) reduction(max : worst)
  for (int k = 0; k < n; ++k) {
    total += block.check[k];
    worst = std::max(worst, block.excess[k]);
  }
  return !(total - total == 0) || worst > 0;
}

}  // namespace treeanim
