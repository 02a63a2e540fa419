// The static deflection of the branches under the step's loads (docs/solver.md, "Bending"):
// the tree as a chain of rigid clusters joined by rotational springs (a Hencky bar chain,
// the discrete Euler-Bernoulli beam), solved exactly in two passes over the cluster tree.
// The global term pulls every vertex toward this deflected pose instead of its rest
// position, so loads bend a branch from its root, as they bend a beam.
#include <omp.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstring>
#include <type_traits>

#include "sim/kernel_isa.h"
#include "sim/lanes.h"
#include "sim/solver_step.h"
#include "sim/turn_series.h"

namespace treeanim {

namespace {

// Rotation vector => rotation matrix (exact for any angle; the identity at 0).
Eigen::Matrix3d rotation_of(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  if (!(angle > 0)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, theta / angle).toRotationMatrix();
}

// The same by Rodrigues' formula, R = cos a I + (sin a / a) [theta]x + ((1 - cos a) / a^2) theta theta^T,
// with a2 = |theta|^2 and the factors sin a / a and (1 - cos a) / a^2 given; R column-major.
// T: a double, or four in lanes (turn_joints_quickly).
template <typename T>
inline void rodrigues(const T& tx, const T& ty, const T& tz, const T& a2, const T& sine, const T& versine, T (&R)[9]) {
  const T vx = versine * tx, vy = versine * ty, vz = versine * tz, diagonal = 1 - versine * a2;
  const T sx = sine * tx, sy = sine * ty, sz = sine * tz;
  R[0] = vx * tx + diagonal, R[1] = vy * tx + sz, R[2] = vz * tx - sy;
  R[3] = vx * ty - sz, R[4] = vy * ty + diagonal, R[5] = vz * ty + sx;
  R[6] = vx * tz + sy, R[7] = vy * tz - sx, R[8] = vz * tz + diagonal;
}

// Rodrigues' factors from their series to a^8 (the next term is below 3e-21) for a turn
// below 0.05 rad (a2 below 0.0025), as far as a joint of the chain turns in an ordinary wind.
// hsm.particles "samples" takes them: its clusters' fixed costs are its step's, and the
// library's sine, cosine and matrix were some 4 % of them; "vertices" keeps the paper's
// set-up byte for byte. Each factor is a product by a constant's reciprocal, not a division:
// a vector division costs several products.
template <typename T>
inline void small_turn_factors(const T& a2, T& sine, T& versine) {
  sine = 1 - a2 * (1.0 / 6) * (1 - a2 * (1.0 / 20) * (1 - a2 * (1.0 / 42) * (1 - a2 * (1.0 / 72))));
  versine = 0.5 * (1 - a2 * (1.0 / 12) * (1 - a2 * (1.0 / 30) * (1 - a2 * (1.0 / 56) * (1 - a2 * (1.0 / 90)))));
}

// Past 0.05 rad, Rodrigues' factors from their longer series (turn_series.h) up to 1.6 rad,
// past the quarter turn that caps every joint's (BarChain::cluster_max_turn). A leaf in a
// breeze turns tenths of a radian, where the library's sine, cosine and matrix took 7 % of
// the samples' demo step in gusts.
constexpr double kWideTurn2 = 2.56;

// A joint's turn => the same turn, at most `largest` long (its yield turn).
Eigen::Vector3d capped_turn(const Eigen::Vector3d& theta, double largest) {
  const double angle = theta.norm();
  return angle > largest ? Eigen::Vector3d(theta * (largest / angle)) : theta;
}

// The air the step's averages left out (AirSample::unresolved) => the six points of an
// unscented transform about the air, +- sqrt(3) sigma_k (sum of sigma_k sigma_k^T: the
// covariance). false when nothing is left out.
bool unresolved_points(const AirSample& air, Eigen::Vector3d (&point)[6]) {
  if (!(air.unresolved.trace() > 0)) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(air.unresolved);
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d sigma = std::sqrt(3 * std::max(eigen.eigenvalues()[k], 0.0)) * eigen.eigenvectors().col(k);
    point[2 * k] = sigma;
    point[2 * k + 1] = -sigma;
  }
  return true;
}

// A joint's turn under the step's mean loads, the load beyond it and its drag per unit |u| u
// (area) with that drag's moment times the compliance (reach), the unscented points and the
// yield turn => the mean of its turns at the points, each at most the yield turn. The loads
// beyond the joint are |u| u per unit area for one relative air u (the velocity's drag
// included); each point changes that air and so |u| u, quadratically. A load that swings
// within the step past the yield turn and across it bends the joint less than its mean
// would; below yield the mean keeps the quadratic drag's second-order rise.
Eigen::Vector3d mean_yielded_turn(const Eigen::Vector3d& theta, const Eigen::Vector3d& load, double area,
                                  const Eigen::Vector3d& reach, const Eigen::Vector3d (&point)[6], double largest) {
  if (!(area > 0)) return capped_turn(theta, largest);
  const Eigen::Vector3d g = load / area;
  const double size = std::sqrt(g.norm());
  const Eigen::Vector3d u = size > 0 ? Eigen::Vector3d(g / size) : Eigen::Vector3d::Zero();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& d : point) {
    const Eigen::Vector3d air = u + d;
    sum += capped_turn(theta + reach.cross(air.norm() * air - g), largest);
  }
  return sum / 6;
}

// A child's weight w and its first moment about its own joint, offset = j_child - j_parent
// => added to its parent's weight and moment about the parent's joint: m_p += m + offset w.
inline void carry_moment(double w, const double* m, const double (&offset)[3], double& parent_w, double* parent_m) {
  parent_w += w;
  for (int i = 0; i < 3; ++i) parent_m[i] += m[i] + offset[i] * w;
}

// A cluster's load sums run in eight fixed lanes: its k-th member is added in lane k % 8, and
// the lanes are added in one fixed order (sum_lanes), so the sums are the same whatever
// vector width the loop runs in (docs/solver.md, "Instruction sets").
constexpr int kLoadLanes = 8;

// Per lane: the force (x, y, z), its moment about the joint (x, y, z), the damping 2 D (the
// largest rate at which the quadratic drag changes with the velocity) and its moment (x, y, z),
// the chain's aerodynamic damping. A cluster of at most four members (a leaf) fills only the
// first four of the eight lanes: it sums in four (sum_lanes), to the same bits.
template <typename Real, int Lanes = kLoadLanes>
struct LoadLanes {
  Real lane[10][Lanes];
};

// Where the load sums read: per vertex the drag, its damping D and 1 / (active memberships);
// per membership whether it is active and its rest arm x0 - joint.
template <typename Real>
struct MemberLoads {
  const Real* force[3];
  const Real* drag_damping;
  const Real* inv_count;
  const uint8_t* active;
  const Real* arm[3];
};

// A member's share (1 / active memberships, 0 when released), its vertex's drag f and damping
// D, its rest arm a => its ten values of LoadLanes: f, a x f, 2 D and 2 D a, each times the
// share. T: a Real, or four members in lanes (sum_four_members).
template <typename T>
inline void member_load(const T& share, const T& fx, const T& fy, const T& fz, const T& drag_damping, const T& ax,
                        const T& ay, const T& az, T (&value)[10]) {
  const T gx = fx * share, gy = fy * share, gz = fz * share;
  const T d = 2 * drag_damping * share;
  value[0] = gx, value[1] = gy, value[2] = gz;
  value[3] = ay * gz - az * gy, value[4] = az * gx - ax * gz, value[5] = ax * gy - ay * gx;
  value[6] = d, value[7] = ax * d, value[8] = ay * d, value[9] = az * d;
}

// A cluster's ten load sums, sum_of(k) for value k => stored where the chain reads them.
template <typename SumOf>
inline void store_cluster_loads(SumOf sum_of, double* load, double* moment, double& damping, double* damping_moment) {
  for (int i = 0; i < 3; ++i) {
    load[i] = sum_of(i);
    moment[i] = sum_of(3 + i);
    damping_moment[i] = sum_of(7 + i);
  }
  damping = sum_of(6);
}

// Membership s of vertex v, `on` 1 when it is active, else 0 => the vertex's share of the loads
// and their moments, added in lane l. `on` comes as a Real: a byte read in the vector loop would
// make GCC run it in 8-byte vectors.
template <typename Real, int Lanes>
inline void add_member_load(const MemberLoads<Real>& in, size_t s, size_t v, Real on, int l,
                            LoadLanes<Real, Lanes>& sum) {
  Real value[10];
  member_load(in.inv_count[v] * on, in.force[0][v], in.force[1][v], in.force[2][v], in.drag_damping[v], in.arm[0][s],
              in.arm[1][s], in.arm[2][s], value);
  for (int k = 0; k < 10; ++k) sum.lane[k][l] += value[k];
}

// Eight lanes => their sum in a fixed order, ((l0 + l4) + (l2 + l6)) + ((l1 + l5) + (l3 + l7)),
// in double; the first four sums in one vector.
template <typename Real>
inline double sum_lanes(const Real (&lane)[kLoadLanes]) {
  typename Lanes4<Real>::type low, high;
  std::memcpy(&low, lane, sizeof low);
  std::memcpy(&high, lane + 4, sizeof high);
  const typename Lanes4<Real>::type pairs = low + high;
  return double((pairs[0] + pairs[2]) + (pairs[1] + pairs[3]));
}
// The first four of them, the others +0: the same sum, since y + (+0) is y for every y but -0,
// and no lane or partial sum is -0 (each lane starts at +0, and x + y is -0 only for two -0).
template <typename Real>
inline double sum_lanes(const Real (&lane)[4]) {
  return double((lane[0] + lane[2]) + (lane[1] + lane[3]));
}

// A cluster of four members on consecutive vertices v..v+3 (a leaf's card), `on` their flags
// => its loads, as add_member_load and the four-lane sum_lanes give them, a member per lane of
// one vector: each lane starts at +0 as LoadLanes does.
template <typename Real>
inline void sum_four_members(const MemberLoads<Real>& in, size_t s, size_t v, const Real (&on)[4], double* load,
                             double* moment, double& damping, double* damping_moment) {
  using V4 = typename Lanes4<Real>::type;
  V4 flags, inv_count, fx, fy, fz, drag_damping, ax, ay, az;
  std::memcpy(&flags, on, sizeof flags);
  std::memcpy(&inv_count, in.inv_count + v, sizeof inv_count);
  std::memcpy(&fx, in.force[0] + v, sizeof fx);
  std::memcpy(&fy, in.force[1] + v, sizeof fy);
  std::memcpy(&fz, in.force[2] + v, sizeof fz);
  std::memcpy(&drag_damping, in.drag_damping + v, sizeof drag_damping);
  std::memcpy(&ax, in.arm[0] + s, sizeof ax);
  std::memcpy(&ay, in.arm[1] + s, sizeof ay);
  std::memcpy(&az, in.arm[2] + s, sizeof az);
  V4 value[10];
  member_load(V4(inv_count * flags), fx, fy, fz, drag_damping, ax, ay, az, value);
  const V4 zero = {};
  store_cluster_loads(
      [&](int k) {
        const V4 lane = zero + value[k];
        return double((lane[0] + lane[2]) + (lane[1] + lane[3]));  // sum_lanes
      },
      load, moment, damping, damping_moment);
}

}  // namespace

template <typename Real>
void sum_drag_areas(const SolverModel<Real>& model, Attachment<Real>& attachment) {
  const TreeModel& tree = model.tree;
  const Eigen::Matrix3Xd& joint = model.chain.cluster_joint;
  attachment.cluster_drag_area.assign(model.C, 0);
  attachment.cluster_drag_arm.setZero(3, model.C);
  for (size_t c = 0; c < model.C; ++c) {
    if (attachment.cluster_flying[c]) continue;
    for (uint32_t s = tree.cluster_offsets[c]; s < tree.cluster_offsets[c + 1]; ++s) {
      if (!attachment.member_active[s]) continue;
      const uint32_t v = tree.cluster_members[s];
      const double a = double(model.vertex_drag[v]) * tree.vertex_mass[v] * double(attachment.vertex_inv_count[v]);
      attachment.cluster_drag_area[c] += a;
      attachment.cluster_drag_arm.col(c) += (tree.rest_positions.col(v) - joint.col(c)) * a;
    }
  }
  for (size_t c = model.C; c-- > 0;) {
    const int32_t p = tree.cluster_parent[c];
    if (p < 0 || attachment.cluster_flying[c]) continue;
    const double offset[3] = {joint(0, c) - joint(0, p), joint(1, c) - joint(1, p), joint(2, c) - joint(2, p)};
    carry_moment(attachment.cluster_drag_area[c], &attachment.cluster_drag_arm(0, c), offset,
                 attachment.cluster_drag_area[p], &attachment.cluster_drag_arm(0, p));
  }
}

namespace {

// Clusters at(0), ..., at(n - 1) => their loads, summed over their members (deflect_bar_chain's 1).
template <typename Real, typename ClusterAt>
void sum_loads(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
               StepScratch<Real>& scratch, size_t n, ClusterAt at) {
  const TreeModel& tree = model.tree;
  const StepPrediction<Real>& prediction = state.prediction<Real>();
  const MemberLoads<Real> loads = {{prediction.drag_force.col(0).data(), prediction.drag_force.col(1).data(),
                                    prediction.drag_force.col(2).data()},
                                   scratch.vertex_drag_damping.data(),
                                   attachment.vertex_inv_count.data(),
                                   attachment.member_active.data(),
                                   {model.member_arm.col(0).data(), model.member_arm.col(1).data(),
                                    model.member_arm.col(2).data()}};
  const uint32_t* members = tree.cluster_members.data();
  // Cluster c's members => their loads summed in `Lanes` lanes, stored.
  auto sum_cluster = [&](size_t c, auto lanes) {
    LoadLanes<Real, decltype(lanes)::value> sum = {};
    // A cluster without released memberships takes every member's flag as 1, read from no byte.
    auto add_loads = [&](auto any_released) {
      const uint32_t begin = tree.cluster_offsets[c], end = tree.cluster_offsets[c + 1];
      for (uint32_t base = begin; base < end; base += kLoadLanes) {
        // Eight members with consecutive vertices (ascending in a cluster) load as vectors.
        const uint32_t n = std::min<uint32_t>(kLoadLanes, end - base), v = members[base];
        Real on[kLoadLanes];
        for (uint32_t l = 0; l < n; ++l) on[l] = any_released ? static_cast<Real>(loads.active[base + l]) : Real(1);
        constexpr int kLanes = decltype(lanes)::value;
        if (n == kLanes && members[base + n - 1] == v + n - 1) {
#pragma omp simd
          for (int l = 0; l < kLanes; ++l) add_member_load(loads, size_t(base) + l, size_t(v) + l, on[l], l, sum);
          continue;
        }
        for (uint32_t l = 0; l < n; ++l) add_member_load(loads, base + l, members[base + l], on[l], int(l), sum);
      }
    };
    if (!attachment.cluster_flying[c]) {
      if (attachment.cluster_released[c])
        add_loads(std::true_type{});
      else
        add_loads(std::false_type{});
    }
    store_cluster_loads([&](int k) { return sum_lanes(sum.lane[k]); }, &scratch.cluster_load(0, c),
                        &scratch.cluster_moment(0, c), scratch.cluster_damping[c], &scratch.cluster_damping_moment(0, c));
  };
  with_kernel_isa([&] {
    for (size_t i = 0; i < n; ++i) {
      const size_t c = at(i);
      const uint32_t begin = tree.cluster_offsets[c], count = tree.cluster_offsets[c + 1] - begin;
      if (count == 4 && !attachment.cluster_flying[c] && members[begin + 3] == members[begin] + 3) {
        Real on[4] = {1, 1, 1, 1};
        if (attachment.cluster_released[c])
          for (int l = 0; l < 4; ++l) on[l] = static_cast<Real>(loads.active[begin + l]);
        sum_four_members(loads, begin, members[begin], on, &scratch.cluster_load(0, c), &scratch.cluster_moment(0, c),
                         scratch.cluster_damping[c], &scratch.cluster_damping_moment(0, c));
        continue;
      }
      if (count <= 4)
        sum_cluster(c, std::integral_constant<int, 4>{});
      else
        sum_cluster(c, std::integral_constant<int, kLoadLanes>{});
    }
  });
}

// What a lane of turn_joints_quickly leaves to the joint's full path.
constexpr uint8_t kQuickTurn = 0, kFullMean = 1, kFullRotation = 2;

// Step 3 of walk_bar_chain for hsm.particles "samples", whose clusters' fixed costs are its
// step's: with `point` the unscented points (nullptr: nothing averaged) and `spread` the
// farthest of them from the air, each joint that no point can turn to its yield takes the mean
// of its uncapped turns, theta + reach x (mean |a| a - g), in one cross product: the same turn
// as mean_yielded_turn's but for round-off, since ||a| a - |u| u| <= (|a| + |u|) |a - u|
// bounds each point's. Its matrix comes from Rodrigues' factors by their series. Four joints
// run at once, a lane each (lanes.h), every lane computing both cases of each choice; the
// joints a point could yield (mean_yielded_turn) and any turned 1.6 rad or more (rotation_of)
// are then taken one by one.
template <typename Real>
void turn_joints_quickly(const SolverModel<Real>& model, const Attachment<Real>& attachment, StepScratch<Real>& scratch,
                         const Eigen::Vector3d (*point)[6], double spread) {
  constexpr size_t kBatch = 64;
  const size_t C = model.C, batches = (C + kBatch - 1) / kBatch;
  const double *compliance = model.chain.cluster_compliance.data(), *max_turn = model.chain.cluster_max_turn.data();
  const double *area = attachment.cluster_drag_area.data(), *arm = attachment.cluster_drag_arm.data();
  const double *moment = scratch.cluster_moment.data(), *load = scratch.cluster_load.data();
  const double* damping_moment = scratch.cluster_damping_moment.data();
  double *path = scratch.cluster_damping_path.data(), *rotation = scratch.cluster_static_rotation.data();
  double d[6][3] = {};
  for (int k = 0; point && k < 6; ++k)
    for (int i = 0; i < 3; ++i) d[k][i] = (*point)[k][i];
#pragma omp for schedule(static)
  for (size_t b = 0; b < batches; ++b) {
    const size_t first = b * kBatch, n = std::min(kBatch, C - first);
    uint8_t full[kBatch];
    double turn[3][kBatch];
    with_kernel_isa([&] {
      for (size_t k = 0; k < n; k += 4) {
        // Lanes past the last joint repeat it; their results are not stored.
        const size_t lanes = std::min<size_t>(4, n - k);
        auto at = [&](const double* values, size_t stride, size_t offset, Double4& v) {
          double lane[4];  // loaded as one vector: an element written into a vector goes through memory
          for (size_t i = 0; i < 4; ++i) lane[i] = values[stride * (first + k + std::min(i, lanes - 1)) + offset];
          std::memcpy(&v, lane, sizeof v);
        };
        Double4 j, largest, m[3], drag_area, g[3], r[3], damping[3];
        at(compliance, 1, 0, j), at(max_turn, 1, 0, largest), at(area, 1, 0, drag_area);
        for (size_t i = 0; i < 3; ++i) {
          at(moment, 3, i, m[i]), at(load, 3, i, g[i]), at(arm, 3, i, r[i]), at(damping_moment, 3, i, damping[i]);
        }
        const Double4 zero = {}, one = zero + 1;
        const Double4 lx = j * m[0], ly = j * m[1], lz = j * m[2];
        Double4 angle = (lx * lx + ly * ly) + lz * lz;
        sqrt_lanes(angle);
        // The damping's own term C_j S_j, with the compliance a joint at its yield turn has left
        // for a moment across its turn (none along it): a yielded joint does not move back.
        const Double4 give = angle > largest ? largest / angle : one;
        // Without a drag area or unresolved air, the capped turn (capped_turn); in air without
        // unresolved gusts (no points) no lane takes the mean, which is then not computed.
        Double4 tx = lx * give, ty = ly * give, tz = lz * give;
        Mask4 yields = {};
        if (point != nullptr) {
          const Mask4 mean = drag_area > zero;
          const Double4 per_area = 1 / drag_area;
          const Double4 gx = g[0] * per_area, gy = g[1] * per_area, gz = g[2] * per_area;
          Double4 size = (gx * gx + gy * gy) + gz * gz;
          sqrt_lanes(size);
          sqrt_lanes(size);
          const Double4 per_size = size > zero ? 1 / size : zero;
          const Double4 ux = gx * per_size, uy = gy * per_size, uz = gz * per_size;
          Double4 fx = zero, fy = zero, fz = zero, fastest = zero;
          for (int p = 0; p < 6; ++p) {
            const Double4 ax = ux + d[p][0], ay = uy + d[p][1], az = uz + d[p][2];
            Double4 speed = (ax * ax + ay * ay) + az * az;
            sqrt_lanes(speed);
            fx += speed * ax, fy += speed * ay, fz += speed * az;
            fastest = fastest < speed ? speed : fastest;  // std::max
          }
          const Double4 rx = j * r[0], ry = j * r[1], rz = j * r[2];
          const Double4 wx = fx * (1.0 / 6) - gx, wy = fy * (1.0 / 6) - gy, wz = fz * (1.0 / 6) - gz;
          tx = mean ? lx + (ry * wz - rz * wy) : tx;
          ty = mean ? ly + (rz * wx - rx * wz) : ty;
          tz = mean ? lz + (rx * wy - ry * wx) : tz;
          Double4 reach = (rx * rx + ry * ry) + rz * rz;
          sqrt_lanes(reach);
          yields = mean & ~(angle + reach * (fastest + size) * spread <= largest);
        }
        const Double4 a2 = (tx * tx + ty * ty) + tz * tz;
        const Mask4 small = a2 < 0.0025, wide = a2 < kWideTurn2;
        const Double4 share = j * give;
        const Double4 px = share * damping[0], py = share * damping[1], pz = share * damping[2];
        Double4 sine, versine, R[9];
        small_turn_factors(a2, sine, versine);
        if (!(small[0] & small[1] & small[2] & small[3])) {  // a bare limb turns little in a breeze
          Double4 wide_sine, wide_versine;
          rodrigues_factors(a2, wide_sine, wide_versine);
          sine = small ? sine : wide_sine, versine = small ? versine : wide_versine;
        }
        rodrigues(tx, ty, tz, a2, sine, versine, R);
        for (size_t i = 0; i < lanes; ++i) {
          const size_t c = first + k + i;
          path[3 * c] = px[i], path[3 * c + 1] = py[i], path[3 * c + 2] = pz[i];
          for (int m = 0; m < 9; ++m) rotation[9 * c + m] = R[m][i];
          turn[0][k + i] = tx[i], turn[1][k + i] = ty[i], turn[2][k + i] = tz[i];
          full[k + i] = yields[i] ? kFullMean : wide[i] ? kQuickTurn : kFullRotation;
        }
      }
    });
    for (size_t k = 0; k < n; ++k) {
      if (full[k] == kQuickTurn) continue;
      const size_t c = first + k;
      const double j = compliance[c];
      Eigen::Vector3d theta;
      if (full[k] == kFullMean) {
        theta = mean_yielded_turn(j * scratch.cluster_moment.col(c), scratch.cluster_load.col(c), area[c],
                                  j * attachment.cluster_drag_arm.col(c), *point, max_turn[c]);
        const double a2 = theta.squaredNorm();
        if (a2 < kWideTurn2) {
          double sine, versine, R[9];
          if (a2 < 0.0025) small_turn_factors(a2, sine, versine);
          else rodrigues_factors(a2, sine, versine);
          rodrigues(theta.x(), theta.y(), theta.z(), a2, sine, versine, R);
          std::copy_n(R, 9, rotation + 9 * c);
          continue;
        }
      } else {
        theta = Eigen::Vector3d(turn[0][k], turn[1][k], turn[2][k]);
      }
      Eigen::Map<Eigen::Matrix3d>(rotation + 9 * c) = rotation_of(theta);
    }
  }
}

}  // namespace

template <typename Real>
void sum_cluster_loads(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                       StepScratch<Real>& scratch, std::span<const uint32_t> clusters) {
  sum_loads(model, attachment, state, scratch, clusters.size(), [&](size_t i) { return size_t(clusters[i]); });
}

template <typename Real>
void deflect_bar_chain(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                       StepScratch<Real>& scratch) {
  // 1. Per cluster: its members' share of the loads, and their moment about its joint. The
  // arms are those of the rest pose: the goal is then a linear function of the loads, with a
  // potential, where arms of the current pose made it a follower load that chased a bent
  // limb round in circles (docs/solver.md, "Bending"); the yield turn bounds large loads.
  // Each thread sums the clusters whose vertices it corrected (balanced_range), in its cache.
  const auto [first, last] = balanced_range(model.tree.cluster_offsets, omp_get_thread_num(), omp_get_num_threads());
  sum_loads(model, attachment, state, scratch, last - first, [first = first](size_t i) { return first + i; });
#pragma omp barrier
  walk_bar_chain(model, attachment, scratch);
}

template <typename Real>
void walk_bar_chain(const SolverModel<Real>& model, const Attachment<Real>& attachment, StepScratch<Real>& scratch) {
  const TreeModel& tree = model.tree;
  const size_t C = model.C;
  const Eigen::Matrix3Xd& joint = model.chain.cluster_joint;
  Eigen::Vector3d unresolved[6];
  const bool averaged = unresolved_points(scratch.air, unresolved);
  double spread = 0;
  for (const Eigen::Vector3d& d : unresolved) spread = averaged ? std::max(spread, d.norm()) : 0.0;
  // 2. Children before parents: a joint carries the moment of everything beyond it. The
  // limbs below the trunk in parallel, then the trunk (BarChain::walk_trunk).
  // In plain doubles, each sum in the order the library's vector expressions took it.
  const double* j = joint.data();
  double *load = scratch.cluster_load.data(), *moment = scratch.cluster_moment.data();
  double *damping = scratch.cluster_damping.data(), *damping_moment = scratch.cluster_damping_moment.data();
  auto carry_up = [&](uint32_t c) {
    const int32_t p = tree.cluster_parent[c];
    if (p < 0 || attachment.cluster_flying[c]) return;
    const double d[3] = {j[3 * c] - j[3 * p], j[3 * c + 1] - j[3 * p + 1], j[3 * c + 2] - j[3 * p + 2]};
    const double* f = load + 3 * c;
    const double arm[3] = {d[1] * f[2] - d[2] * f[1], d[2] * f[0] - d[0] * f[2], d[0] * f[1] - d[1] * f[0]};
    for (int i = 0; i < 3; ++i) {
      load[3 * p + i] += f[i];
      moment[3 * p + i] += moment[3 * c + i] + arm[i];
    }
    carry_moment(damping[c], damping_moment + 3 * c, d, damping[p], damping_moment + 3 * p);
  };
  const BarChain& chain = model.chain;
  const size_t groups = chain.walk_group_offsets.size() - 1;
#pragma omp for schedule(static)
  for (size_t g = 0; g < groups; ++g)
    for (uint32_t k = chain.walk_group_offsets[g + 1]; k-- > chain.walk_group_offsets[g];) carry_up(chain.walk_groups[k]);
#pragma omp single
  for (size_t k = chain.walk_trunk.size(); k-- > 0;) carry_up(chain.walk_trunk[k]);
  // 3. Parents before children: each joint turns by its compliance times its moment (in
  // parallel: the sines and cosines), and the turns accumulate from the root (the trunk, then
  // the limbs), as do the damping's sums over the joints from the root, C_j S_j and C_j S_j . (j_c - j_j)
  // (about the cluster's own joint: small numbers wherever the tree stands).
  if (model.quick_chain) {
    turn_joints_quickly(model, attachment, scratch, averaged ? &unresolved : nullptr, spread);
  } else {
#pragma omp for schedule(static)
    for (size_t c = 0; c < C; ++c) {
      const double compliance = model.chain.cluster_compliance[c];
      const Eigen::Vector3d loaded = compliance * scratch.cluster_moment.col(c);
      const double angle = loaded.norm(), largest = model.chain.cluster_max_turn[c];
      const double give = angle > largest ? largest / angle : 1.0;  // as turn_joints_quickly's
      const Eigen::Vector3d theta =
          averaged ? mean_yielded_turn(loaded, scratch.cluster_load.col(c), attachment.cluster_drag_area[c],
                                       compliance * attachment.cluster_drag_arm.col(c), unresolved, largest)
                   : capped_turn(loaded, largest);
      scratch.cluster_damping_path.col(c) = (compliance * give) * scratch.cluster_damping_moment.col(c);
      Eigen::Map<Eigen::Matrix3d>(&scratch.cluster_static_rotation(0, c)) = rotation_of(theta);
    }
  }
  // The trunk on one thread, then the limbs below it in parallel.
  double *rotation = scratch.cluster_static_rotation.data(), *moved_joint = scratch.cluster_static_joint.data();
  double *path = scratch.cluster_damping_path.data(), *lever = scratch.cluster_damping_lever.data();
  auto carry_down = [&](uint32_t c) {
    const int32_t p = tree.cluster_parent[c];
    if (p < 0 || attachment.cluster_flying[c]) {
      for (int i = 0; i < 3; ++i) moved_joint[3 * c + i] = j[3 * c + i];
      lever[c] = 0;
      return;
    }
    const double d[3] = {j[3 * c] - j[3 * p], j[3 * c + 1] - j[3 * p + 1], j[3 * c + 2] - j[3 * p + 2]};
    for (int i = 0; i < 3; ++i) path[3 * c + i] += path[3 * p + i];
    lever[c] = lever[p] + ((path[3 * p] * d[0] + path[3 * p + 1] * d[1]) + path[3 * p + 2] * d[2]);
    // The joint's move, parent d, and the turn down the chain, R parent, as the library sums them.
    const double* parent = rotation + 9 * p;
    double* R = rotation + 9 * c;
    for (int i = 0; i < 3; ++i) {
      double turned;
      matrix_row_sum(i, parent[i] * d[0], parent[i + 3] * d[1], parent[i + 6] * d[2], turned);
      moved_joint[3 * c + i] = moved_joint[3 * p + i] + turned;
    }
    double product[9];
    for (int col = 0; col < 3; ++col)
      for (int i = 0; i < 3; ++i) {
        const double* column = parent + 3 * col;
        matrix_row_sum(i, R[i] * column[0], R[i + 3] * column[1], R[i + 6] * column[2], product[i + 3 * col]);
      }
    std::copy_n(product, 9, R);
  };
#pragma omp single
  for (uint32_t c : chain.walk_trunk) carry_down(c);
#pragma omp for schedule(static)
  for (size_t g = 0; g < groups; ++g)
    for (uint32_t k = chain.walk_group_offsets[g]; k < chain.walk_group_offsets[g + 1]; ++k)
      carry_down(chain.walk_groups[k]);
  // Each cluster's deflected pose as the goal writes read it, in Real: R - I, the joint's move
  // J - j, the damping path and lever (small numbers: the goal is an offset from rest).
#pragma omp for schedule(static)
  for (size_t c = 0; c < C; ++c) {
    Real* pose = &scratch.cluster_pose(0, c);
    for (int i = 0; i < 9; ++i) pose[i] = static_cast<Real>(scratch.cluster_static_rotation(i, c) - (i % 4 == 0));
    for (int i = 0; i < 3; ++i) {
      pose[9 + i] = static_cast<Real>(scratch.cluster_static_joint(i, c) - joint(i, c));
      pose[12 + i] = static_cast<Real>(scratch.cluster_damping_path(i, c));
    }
    pose[15] = static_cast<Real>(scratch.cluster_damping_lever[c]);
  }
}

namespace {

// Rest arm (ax, ay, az) from the joint of a cluster with deflected pose k (StepScratch::
// cluster_pose) => its offset from rest in the deflected pose, (R - I) a + J - j, and
// C_j S_j . a + lever, added to the sums. T: a Real, or four vertices in lanes (write_card).
template <typename Real, typename T>
inline void add_deflected(const Real* k, const T& ax, const T& ay, const T& az, T& ox, T& oy, T& oz, T& back) {
  ox += ((k[0] * ax + k[3] * ay) + k[6] * az) + k[9];
  oy += ((k[1] * ax + k[4] * ay) + k[7] * az) + k[10];
  oz += ((k[2] * ax + k[5] * ay) + k[8] * az) + k[11];
  back += ((k[12] * ax + k[13] * ay) + k[14] * az) + k[15];
}

// Where the goal writes go: per vertex its goal (prediction.goal) and damping compliance.
template <typename Real>
struct GoalRows {
  Real *x, *y, *z, *compliance;
};

// Vertex v's sums over its clusters and share = 1 / their number => its goal, the mean, and
// its damping compliance, never below 0.
template <typename Real>
inline void store_goal(const GoalRows<Real>& out, size_t v, Real ox, Real oy, Real oz, Real back, Real share) {
  out.x[v] = ox * share, out.y[v] = oy * share, out.z[v] = oz * share;
  out.compliance[v] = std::max(back * share, Real(0));
}

// Vertices [v, stop) of `run`, which holds N clusters => their goals and damping compliances,
// each the vertex loop's sum over its memberships in order, the lanes vectorised. A mean over
// one takes the share 1 as a constant.
template <int N, typename Real>
void write_run(const SolverModel<Real>& model, const Attachment<Real>& attachment, const StepScratch<Real>& scratch,
               const GoalRows<Real>& out, const VertexRun& run, size_t v, size_t stop) {
  static_assert(N >= 1 && N <= int(kMaxRunClusters));
  const Real* k[N];
  const Real *ax[N], *ay[N], *az[N];
  for (int j = 0; j < N; ++j) {
    const uint32_t slot = run.first_slot[j];
    k[j] = &scratch.cluster_pose(0, run.cluster[j]);
    ax[j] = model.member_arm.col(0).data() + slot - run.begin;
    ay[j] = model.member_arm.col(1).data() + slot - run.begin;
    az[j] = model.member_arm.col(2).data() + slot - run.begin;
  }
  const Real* inv_count = attachment.vertex_inv_count.data();
#pragma omp simd
  for (size_t u = v; u < stop; ++u) {
    Real ox = 0, oy = 0, oz = 0, back = 0;
    for (int j = 0; j < N; ++j) add_deflected(k[j], ax[j][u], ay[j][u], az[j][u], ox, oy, oz, back);
    store_goal(out, u, ox, oy, oz, back, N == 1 ? Real(1) : inv_count[u]);
  }
}

// A leaf's card => its four vertices' goals and damping compliances, a vertex per lane, each
// lane the vertex loop's sums over its memberships in order (the shared vertex's branch
// first): a released membership adds nothing, an absent one +0, which leaves every sum as it
// was (0 + x is -0 only for x = -0 and 0, so adding +0 after it changes nothing).
template <typename Real>
void write_card(const SolverModel<Real>& model, const Attachment<Real>& attachment, const StepScratch<Real>& scratch,
                const GoalRows<Real>& out, const LeafCard& card) {
  using V4 = typename Lanes4<Real>::type;
  const V4 zero = {};
  V4 ax, ay, az, share;
  std::memcpy(&ax, model.member_arm.col(0).data() + card.slot, sizeof ax);
  std::memcpy(&ay, model.member_arm.col(1).data() + card.slot, sizeof ay);
  std::memcpy(&az, model.member_arm.col(2).data() + card.slot, sizeof az);
  std::memcpy(&share, attachment.vertex_inv_count.data() + card.vertex, sizeof share);
  const uint8_t* active = attachment.member_active.data();
  V4 ox = zero, oy = zero, oz = zero, back = zero;
  if (active[card.pin_slot]) {
    const size_t s = card.pin_slot;
    Real x = 0, y = 0, z = 0, b = 0;
    add_deflected(&scratch.cluster_pose(0, card.pin_cluster), model.member_arm(s, 0), model.member_arm(s, 1),
                  model.member_arm(s, 2), x, y, z, b);
    ox[0] = x, oy[0] = y, oz[0] = z, back[0] = b;
  }
  // The card's own terms, each 0 + term: +0 for -0, which the sum after 0 or after the
  // shared vertex's branch term takes as the term itself.
  V4 tx = zero, ty = zero, tz = zero, tb = zero, on;
  add_deflected(&scratch.cluster_pose(0, card.cluster), ax, ay, az, tx, ty, tz, tb);
  for (int l = 0; l < 4; ++l) on[l] = active[card.slot + l] ? Real(1) : Real(0);
  const auto kept = on != zero;
  ox += kept ? tx : zero, oy += kept ? ty : zero, oz += kept ? tz : zero, back += kept ? tb : zero;
  ox *= share, oy *= share, oz *= share, back *= share;
  back = back < zero ? zero : back;  // std::max(back, 0)
  std::memcpy(out.x + card.vertex, &ox, sizeof ox);
  std::memcpy(out.y + card.vertex, &oy, sizeof oy);
  std::memcpy(out.z + card.vertex, &oz, sizeof oz);
  std::memcpy(out.compliance + card.vertex, &back, sizeof back);
}

}  // namespace

template <typename Real>
void write_static_offsets(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                          const StepScratch<Real>& scratch, StepPrediction<Real>& prediction, size_t begin,
                          size_t end) {
  const TreeModel& tree = model.tree;
  // 4. Per vertex: the mean over its clusters of their deflected poses, as an offset from rest;
  // and the mean of sum_j C_j S_j . (x0 - j_j), the goal's move back per m/s of the vertex when
  // everything moves with it (docs/solver.md, "Aerodynamic damping"). A run of vertices in the
  // same clusters, whose memberships are consecutive in each (SolverModel::vertex_runs), is
  // one loop on those clusters' poses, vectorised, with the operations of the vertex loop.
  const Real *arm_x = model.member_arm.col(0).data(), *arm_y = model.member_arm.col(1).data(),
             *arm_z = model.member_arm.col(2).data();
  const uint32_t *offsets = tree.vertex_cluster_offsets.data(), *memberships = tree.vertex_memberships.data();
  const uint32_t* member_cluster = model.tree.member_cluster.data();
  const uint8_t* active = attachment.member_active.data();
  const GoalRows<Real> out = {prediction.goal.col(0).data(), prediction.goal.col(1).data(),
                              prediction.goal.col(2).data(), prediction.damping_compliance.data()};
  const std::vector<VertexRun>& runs = model.vertex_runs;
  const std::vector<LeafCard>& cards = model.leaf_cards;
  with_kernel_isa([&] {
    auto run = std::upper_bound(runs.begin(), runs.end(), begin,
                                [](size_t v, const VertexRun& r) { return v < r.end; });  // the first ending after begin
    auto card = std::lower_bound(cards.begin(), cards.end(), begin,
                                 [](const LeafCard& c, size_t v) { return c.vertex < v; });  // the first from begin
    for (size_t v = begin; v < end;) {
      // A card across the range's end is taken vertex by vertex below, to the same bits.
      if (card != cards.end() && card->vertex == v && v + 4 <= end) {
        write_card(model, attachment, scratch, out, *card++);
        v += 4;
        continue;
      }
      if (run != runs.end() && run->begin <= v) {
        const size_t stop = std::min<size_t>(run->end, end);
        switch (run->count) {
          case 1: write_run<1>(model, attachment, scratch, out, *run, v, stop); break;
          case 2: write_run<2>(model, attachment, scratch, out, *run, v, stop); break;
          case 3: write_run<3>(model, attachment, scratch, out, *run, v, stop); break;
          default: write_run<kMaxRunClusters>(model, attachment, scratch, out, *run, v, stop); break;
        }
        if (stop == run->end) ++run;
        v = stop;
        continue;
      }
      Real ox = 0, oy = 0, oz = 0, back = 0;
      for (uint32_t s = offsets[v]; s < offsets[v + 1]; ++s) {
        const uint32_t slot = memberships[s];
        if (!active[slot]) continue;
        add_deflected(&scratch.cluster_pose(0, member_cluster[slot]), arm_x[slot], arm_y[slot], arm_z[slot], ox, oy,
                      oz, back);
      }
      store_goal(out, v, ox, oy, oz, back, attachment.vertex_inv_count[v]);
      ++v;
    }
  });
}

#define TREEANIM_BEAM_STATICS(Real)                                                                               \
  template void sum_drag_areas(const SolverModel<Real>&, Attachment<Real>&);                                       \
  template void deflect_bar_chain(const SolverModel<Real>&, const Attachment<Real>&, const SimState&,              \
                                  StepScratch<Real>&);                                                              \
  template void sum_cluster_loads(const SolverModel<Real>&, const Attachment<Real>&, const SimState&,              \
                                  StepScratch<Real>&, std::span<const uint32_t>);                                   \
  template void walk_bar_chain(const SolverModel<Real>&, const Attachment<Real>&, StepScratch<Real>&);             \
  template void write_static_offsets(const SolverModel<Real>&, const Attachment<Real>&, const StepScratch<Real>&, \
                                     StepPrediction<Real>&, size_t, size_t);
TREEANIM_BEAM_STATICS(float)
TREEANIM_BEAM_STATICS(double)
#undef TREEANIM_BEAM_STATICS

}  // namespace treeanim
