// The mesh of hsm.particles "samples" placed from its clusters' frames (docs/solver.md,
// "Particles"): a rigid fit per cluster to its samples, then every mesh vertex from its clusters.
#include "sim/sample_skin.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cstring>

#include "sim/kernel_isa.h"
#include "sim/rotation.h"
#include "sim/solver_model.h"

namespace treeanim {

namespace {

// A cluster's frame as pose reads it: R - I, its rest centre t0 and shift, and (with
// velocities) its centre's velocity and its spin.
struct PlacedFrame {
  Eigen::Matrix3d turned;
  Eigen::Vector3d centre, shift, velocity, spin;

  // A vertex at rest x0 => its move in this frame, R (x0 - t0) + t0 + shift - x0, and its
  // velocity, added to the sums.
  void add_move(const Eigen::Vector3d& x0, bool velocities, Eigen::Vector3d& move, Eigen::Vector3d& speed) const {
    const Eigen::Vector3d arm = x0 - centre;
    move += turned * arm + shift;
    if (velocities) speed += velocity + spin.cross(turned * arm + arm);
  }
};

// Vertices [begin, end) at rest (3 x V, column-major), in the N clusters of `cluster` => their
// places (3 x V, in Out), x0 + the mean of R (x0 - t0) + t0 + shift - x0 over the clusters:
// PlacedFrame::add_move's arithmetic in plain doubles, the library's order kept
// (matrix_row_sum), so that the loop runs in vector lanes.
template <int N, typename Out>
void place_run(const PlacedFrame (&cluster)[kMaxRunClusters], const double* rest, uint32_t begin, uint32_t end,
               Out* positions) {
  double t[N][9], centre[N][3], shift[N][3];
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < 3; ++i) {
      for (int k = 0; k < 3; ++k) t[j][i + 3 * k] = cluster[j].turned(i, k);
      centre[j][i] = cluster[j].centre[i];
      shift[j][i] = cluster[j].shift[i];
    }
#pragma omp simd
  for (uint32_t v = begin; v < end; ++v) {
    const double x0[3] = {rest[3 * v], rest[3 * v + 1], rest[3 * v + 2]};
    double move[3] = {0, 0, 0};
    for (int j = 0; j < N; ++j) {
      const double* T = t[j];
      const double arm[3] = {x0[0] - centre[j][0], x0[1] - centre[j][1], x0[2] - centre[j][2]};
      for (int i = 0; i < 3; ++i) {
        double turned;
        matrix_row_sum(i, T[i] * arm[0], T[i + 3] * arm[1], T[i + 6] * arm[2], turned);
        move[i] += turned + shift[j][i];
      }
    }
    for (int i = 0; i < 3; ++i) {
      if constexpr (N > 1) move[i] /= N;
      positions[3 * v + i] = static_cast<Out>(x0[i] + move[i]);
    }
  }
}

// Iterations of the frame's rotation: warm-started from the solver's last fit of the same
// samples, it converges in one or two.
constexpr int kFrameIterations = 12;

}  // namespace

SampleSkin::SampleSkin(const TreeModel& mesh, const TreeModel& samples) : mesh_(mesh), samples_(samples) {
  const size_t C = samples.cluster_count(), V = mesh.vertex_count();
  fit_offsets_.assign(1, 0);
  rest_centre_.setZero(3, long(C));
  match_scale_.assign(C, 0);
  std::vector<Eigen::Vector3d> offsets;
  for (size_t c = 0; c < C; ++c) {
    // A branch fits its own samples: a leaf's shared vertex moves with the leaf as well.
    const int32_t leaf = samples.cluster_kind[c] == kClusterLeaf ? samples.cluster_leaf[c] : -1;
    const size_t first = fit_samples_.size();
    double mass = 0;
    for (uint32_t i = samples.cluster_offsets[c]; i < samples.cluster_offsets[c + 1]; ++i) {
      const uint32_t s = samples.cluster_members[i];
      if (samples.vertex_leaf[s] != leaf) continue;
      fit_samples_.push_back(s);
      mass += samples.vertex_mass[s];
    }
    if (fit_samples_.size() == first)  // none of its own: every member
      for (uint32_t i = samples.cluster_offsets[c]; i < samples.cluster_offsets[c + 1]; ++i) {
        fit_samples_.push_back(samples.cluster_members[i]);
        mass += samples.vertex_mass[samples.cluster_members[i]];
      }
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (size_t k = first; k < fit_samples_.size(); ++k) {
      const uint32_t s = fit_samples_[k];
      fit_weight_.push_back(samples.vertex_mass[s] / mass);
      centre += fit_weight_.back() * samples.rest_positions.col(s);
    }
    rest_centre_.col(long(c)) = centre;
    double spread = 0;
    for (size_t k = first; k < fit_samples_.size(); ++k) {
      offsets.push_back(samples.rest_positions.col(fit_samples_[k]) - centre);
      spread += fit_weight_[k] * offsets.back().squaredNorm();
    }
    match_scale_[c] = spread > 0 ? 1 / spread : 0;
    fit_offsets_.push_back(uint32_t(fit_samples_.size()));
  }
  fit_offset_.resize(3, long(offsets.size()));
  for (size_t k = 0; k < offsets.size(); ++k) fit_offset_.col(long(k)) = offsets[k];
  rest_moment_.setZero(9, long(C));
  offset_sum_.setZero(3, long(C));
  for (size_t c = 0; c < C; ++c)
    for (uint32_t k = fit_offsets_[c]; k < fit_offsets_[c + 1]; ++k) {
      const Eigen::Vector3d q = fit_offset_.col(k);
      const double w = fit_weight_[k];
      offset_sum_.col(long(c)) += w * q;
      Eigen::Map<Eigen::Matrix3d> rest(&rest_moment_(0, long(c)));
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) rest(i, j) += w * (q[i] * q[j]);
    }
  petiole_leaf_.assign(V, -1);
  for (size_t l = 0; l < mesh.leaf_count(); ++l) petiole_leaf_[mesh.leaf_attachment_vertex[l]] = int32_t(l);
  std::vector<uint8_t> single(V, 0);
  for (size_t v = 0; v < V; ++v) single[v] = mesh.vertex_anchored[v] || petiole_leaf_[v] >= 0;
  runs_ = vertex_runs(mesh, single);
  std::vector<uint8_t> in_run(V, 0);
  for (const VertexRun& run : runs_) std::fill(in_run.begin() + run.begin, in_run.begin() + run.end, 1);
  for (uint32_t v = 0; v < V; ++v)
    if (!in_run[v]) single_vertices_.push_back(v);
}

void SampleSkin::fit_frames(const SimState& state, bool velocities, ClusterFrames& frames) const {
  const long C = long(samples_.cluster_count());
  frames.rotation.resize(4, C);
  frames.shift.resize(3, C);
  if (velocities) {
    frames.velocity.resize(3, C);
    frames.spin.resize(3, C);
  }
  // On several threads from as many memberships as the solver's loops (kParallelMemberships),
  // four clusters at a time: the rotations of those that moved are found together, a lane each.
  const long groups = (C + 3) / 4;
#pragma omp parallel for schedule(static) if (fit_samples_.size() >= kParallelMemberships)
  for (long g = 0; g < groups; ++g) {
    const long first = 4 * g, last = std::min(C, first + 4);
    double a_lanes[9][4], q_lanes[4][4];  // loaded as vectors whole, below
    long moving[4];
    int lanes = 0;
    for (long c = first; c < last; ++c) {
      // A = sum s (d - shift) q^T with d = u + q, u = x - x0: sum s u q^T + the rest moment
      // sum s q q^T - shift (sum s q)^T, s = w k; at rest exactly the symmetric rest moment.
      // In plain doubles, each sum as the library's expressions took it.
      double shift[3] = {}, moved[9] = {};  // moved column-major
      bool at_rest = true;
      for (uint32_t k = fit_offsets_[c]; k < fit_offsets_[c + 1]; ++k) {
        const uint32_t s = fit_samples_[k];
        const double* q = &fit_offset_(0, k);
        const double w = fit_weight_[k];
        double wu[3];
        for (int i = 0; i < 3; ++i) {
          const double u = state.positions(i, s) - samples_.rest_positions(i, s);
          at_rest = at_rest && u == 0;
          wu[i] = w * u;
          shift[i] += wu[i];
        }
        for (int j = 0; j < 3; ++j)
          for (int i = 0; i < 3; ++i) moved[i + 3 * j] += wu[i] * q[j];
      }
      for (int i = 0; i < 3; ++i) frames.shift(i, c) = shift[i];
      frames.rotation.col(c) = Eigen::Quaterniond::Identity().coeffs();
      if (at_rest) continue;
      const double* offset_sum = &offset_sum_(0, c);
      const double* rest = &rest_moment_(0, c);
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
          a_lanes[i + 3 * j][lanes] = ((moved[i + 3 * j] + rest[i + 3 * j]) - shift[i] * offset_sum[j]) * match_scale_[c];
      const Eigen::Vector4d warm = state.cluster_rotations.col(c);
      Eigen::Quaterniond rotation(warm[3], warm[0], warm[1], warm[2]);
      if (!(rotation.norm() > 0.5)) rotation = Eigen::Quaterniond::Identity();
      rotation.normalize();
      for (int k = 0; k < 4; ++k) q_lanes[k][lanes] = rotation.coeffs()[k];
      moving[lanes++] = c;
    }
    if (lanes > 0) {
      for (int l = lanes; l < 4; ++l) {  // lanes without a cluster repeat the first
        for (int i = 0; i < 9; ++i) a_lanes[i][l] = a_lanes[i][0];
        for (int k = 0; k < 4; ++k) q_lanes[k][l] = q_lanes[k][0];
      }
      Double4 A[9], q[4];
      std::memcpy(A, a_lanes, sizeof A);
      std::memcpy(q, q_lanes, sizeof q);
      extract_rotations(A, q, kFrameIterations);
      for (int l = 0; l < lanes; ++l)
        for (int k = 0; k < 4; ++k) frames.rotation(k, moving[l]) = q[k][l];
    }
    for (long c = first; c < last && velocities; ++c) {
      const Eigen::Vector4d coeffs = frames.rotation.col(c);
      const Eigen::Quaterniond rotation(coeffs[3], coeffs[0], coeffs[1], coeffs[2]);
      // The rigid motion nearest the samples' velocities: the centre's, and the spin whose
      // angular momentum about the centre is theirs.
      const Eigen::Matrix3d R = rotation.toRotationMatrix();
      Eigen::Vector3d velocity = Eigen::Vector3d::Zero(), momentum = Eigen::Vector3d::Zero();
      Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
      for (uint32_t k = fit_offsets_[c]; k < fit_offsets_[c + 1]; ++k)
        velocity += fit_weight_[k] * state.velocities.col(fit_samples_[k]);
      for (uint32_t k = fit_offsets_[c]; k < fit_offsets_[c + 1]; ++k) {
        const Eigen::Vector3d r = R * fit_offset_.col(k);
        const double w = fit_weight_[k];
        momentum += w * r.cross(state.velocities.col(fit_samples_[k]) - velocity);
        inertia += w * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
      }
      Eigen::Vector3d spin = Eigen::Vector3d::Zero();
      const double size = inertia.trace();
      if (size > 0 && std::abs(inertia.determinant()) > 1e-9 * size * size * size) spin = inertia.inverse() * momentum;
      frames.velocity.col(c) = velocity;
      frames.spin.col(c) = spin;
    }
  }
}

void SampleSkin::pose(const SimState& state, bool velocities, ClusterFrames& frames, SimState& out) const {
  const long V = long(mesh_.vertex_count());
  out.positions.resize(3, V);
  out.velocities.resize(3, velocities ? V : 0);
  place(state, frames, out.positions.data(), velocities ? out.velocities.data() : nullptr);
  out.time = state.time;
  out.leaf_attached = state.leaf_attached;
}

void SampleSkin::pose(const SimState& state, ClusterFrames& frames, float* positions, float* velocities) const {
  place(state, frames, positions, velocities);
}

template <typename Out>
void SampleSkin::place(const SimState& state, ClusterFrames& frames, Out* positions, Out* velocities) const {
  const bool with_velocities = velocities != nullptr;
  fit_frames(state, with_velocities, frames);
  const long C = long(samples_.cluster_count());
  // (R - I) per cluster, column-major, so each vertex reads nine numbers.
  Eigen::Matrix<double, 9, Eigen::Dynamic> turn(9, C);
  for (long c = 0; c < C; ++c) {
    const Eigen::Vector4d q = frames.rotation.col(c);
    Eigen::Matrix3d R = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).toRotationMatrix();
    if (q == Eigen::Vector4d(0, 0, 0, 1)) R.setIdentity();
    R -= Eigen::Matrix3d::Identity();
    turn.col(c) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(R.data());
  }
  // Cluster c's frame as a vertex reads it: (R - I), rest centre, shift, and the motion.
  auto frame_of = [&](uint32_t c) {
    PlacedFrame f{Eigen::Map<const Eigen::Matrix3d>(&turn(0, c)), rest_centre_.col(c), frames.shift.col(c), {}, {}};
    if (!with_velocities) return f;
    f.velocity = frames.velocity.col(c);
    f.spin = frames.spin.col(c);
    return f;
  };
  // Vertex v at rest x0 and the sums of its `count` clusters' moves => its place, their mean.
  auto put = [&](uint32_t v, const Eigen::Vector3d& x0, Eigen::Vector3d move, Eigen::Vector3d speed, int count) {
    if (count > 1) {
      move /= count;
      speed /= count;
    }
    for (int a = 0; a < 3; ++a) positions[3 * v + a] = static_cast<Out>(x0[a] + move[a]);
    if (velocities)
      for (int a = 0; a < 3; ++a) velocities[3 * v + a] = static_cast<Out>(speed[a]);
  };
  const bool parallel = mesh_.membership_count() >= kParallelMemberships;
  // A run: its clusters' frames read once, then each vertex in the order of its memberships;
  // without velocities in vector lanes (place_run).
#pragma omp parallel for schedule(static) if (parallel)
  for (size_t r = 0; r < runs_.size(); ++r) {
    const VertexRun& run = runs_[r];
    PlacedFrame cluster[kMaxRunClusters];
    for (uint32_t j = 0; j < run.count; ++j) cluster[j] = frame_of(run.cluster[j]);
    if (!velocities) {
      with_kernel_isa([&] {
        switch (run.count) {
          case 1: place_run<1>(cluster, mesh_.rest_positions.data(), run.begin, run.end, positions); break;
          case 2: place_run<2>(cluster, mesh_.rest_positions.data(), run.begin, run.end, positions); break;
          case 3: place_run<3>(cluster, mesh_.rest_positions.data(), run.begin, run.end, positions); break;
          default:
            place_run<kMaxRunClusters>(cluster, mesh_.rest_positions.data(), run.begin, run.end, positions);
        }
      });
      continue;
    }
    for (uint32_t v = run.begin; v < run.end; ++v) {
      const Eigen::Vector3d x0 = mesh_.rest_positions.col(v);
      Eigen::Vector3d move = Eigen::Vector3d::Zero(), speed = Eigen::Vector3d::Zero();
      for (uint32_t j = 0; j < run.count; ++j) cluster[j].add_move(x0, with_velocities, move, speed);
      put(v, x0, move, speed, int(run.count));
    }
  }
#pragma omp parallel for schedule(static) if (parallel)
  for (size_t i = 0; i < single_vertices_.size(); ++i) {
    const uint32_t v = single_vertices_[i];
    const Eigen::Vector3d x0 = mesh_.rest_positions.col(v);
    if (mesh_.vertex_anchored[v]) {  // fixed to the ground, as the solver holds it
      for (int a = 0; a < 3; ++a) positions[3 * v + a] = static_cast<Out>(x0[a]);
      if (velocities)
        for (int a = 0; a < 3; ++a) velocities[3 * v + a] = 0;
      continue;
    }
    Eigen::Vector3d move = Eigen::Vector3d::Zero(), speed = Eigen::Vector3d::Zero();
    int count = 0;
    const int32_t leaf = petiole_leaf_[v];
    // A detached leaf's shared vertex keeps the side it was built for (detachment.cpp).
    const bool released = leaf >= 0 && !state.leaf_attached[leaf];
    const bool goes_with_leaf = released && mesh_.vertex_leaf[v] == leaf;
    for (uint32_t k = mesh_.vertex_cluster_offsets[v]; k < mesh_.vertex_cluster_offsets[v + 1]; ++k) {
      const uint32_t c = mesh_.member_cluster[mesh_.vertex_memberships[k]];
      if (released && (c == mesh_.leaf_cluster[leaf]) != goes_with_leaf) continue;
      frame_of(c).add_move(x0, with_velocities, move, speed);
      ++count;
    }
    put(v, x0, move, speed, count);
  }
}

}  // namespace treeanim
