// Branch mesh: one ring per axis joint, truncated cones between them, closed tips.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "tree/tree_build_steps.h"

namespace treeanim {
namespace {

// Longest stretch of a mitred joint ring; a near reversal of the axis would otherwise blow up.
constexpr double kMaxMitreStretch = 3.0;

// u (any vector) and unit tangent t => unit vector perpendicular to t, closest to u.
Eigen::Vector3d perpendicular(const Eigen::Vector3d& u, const Eigen::Vector3d& t) {
  const Eigen::Vector3d p = u - u.dot(t) * t;
  const double n = p.norm();
  return n > 1e-9 ? Eigen::Vector3d(p / n) : Eigen::Vector3d(t.unitOrthogonal());
}

// Parallel transport: normal n at unit tangent a => n rotated by the minimal rotation a => b.
// Minimal rotations never twist the frame about the axis, so rings along a curved or helical
// axis neither flip nor spin (Bishop frame). Rodrigues' formula without trigonometry.
Eigen::Vector3d transport(const Eigen::Vector3d& n, const Eigen::Vector3d& a,
                          const Eigen::Vector3d& b) {
  const double c = a.dot(b);
  if (c <= -1.0 + 1e-12) return perpendicular(n, b);  // reversal: no unique rotation
  const Eigen::Vector3d k = a.cross(b);
  const Eigen::Vector3d r = n * c + k.cross(n) + k * (k.dot(n) / (1.0 + c));
  return perpendicular(r, b);  // removes rounding drift
}

// Geometry of one ring.
struct Ring {
  Eigen::Vector3d centre;   // m
  Eigen::Vector3d tangent;  // unit, ring plane normal
  Eigen::Vector3d normal;   // unit, direction of the ring's vertex 0
  Eigen::Vector3d bend;     // unit in-plane direction of the mitre stretch (zero: none)
  double stretch = 1.0;     // mitre factor along `bend`
  double radius = 0.0;      // m
  double v = 0.0;           // m, arc length along the axis (texture v)
};

// A joint between unit directions d_in and d_out => ring tangent (bisector) and mitre, so the
// tube keeps its cross-section through a bend instead of pinching.
void set_joint(Ring& ring, const Eigen::Vector3d& d_in, const Eigen::Vector3d& d_out) {
  const Eigen::Vector3d sum = d_in + d_out;
  const double half_cos = 0.5 * sum.norm();
  if (half_cos < 1e-6) {  // the axis folds back on itself
    ring.tangent = d_in;
    ring.bend.setZero();
    ring.stretch = 1.0;
    return;
  }
  ring.tangent = sum / (2.0 * half_cos);
  const Eigen::Vector3d turn = d_out - d_in;
  const double turn_norm = turn.norm();
  ring.bend = turn_norm > 1e-12 ? Eigen::Vector3d(turn / turn_norm) : Eigen::Vector3d::Zero();
  ring.stretch = std::min(1.0 / half_cos, kMaxMitreStretch);
}

// Precomputed cos/sin of the ring angles.
struct RingAngles {
  std::vector<double> c, s;
  explicit RingAngles(int sides) : c(sides), s(sides) {
    for (int k = 0; k < sides; ++k) {
      const double a = 2.0 * std::numbers::pi * k / sides;
      c[k] = std::cos(a);
      s[k] = std::sin(a);
    }
  }
};

// ring => sides vertices from `first` on, counter-clockwise about the tangent (their UVs with
// the surface).
void write_ring(const Ring& ring, const RingAngles& angles, uint32_t first, int32_t segment, bool surface,
                TreeModel& model) {
  const int sides = int(angles.c.size());
  const Eigen::Vector3d binormal = ring.tangent.cross(ring.normal);
  for (int k = 0; k < sides; ++k) {
    Eigen::Vector3d o = ring.radius * (angles.c[k] * ring.normal + angles.s[k] * binormal);
    o += (ring.stretch - 1.0) * o.dot(ring.bend) * ring.bend;
    const uint32_t v = first + uint32_t(k);
    model.rest_positions.col(v) = ring.centre + o;
    if (surface) model.uvs.col(v) = Eigen::Vector2f(float(k) / float(sides), float(ring.v));
    model.vertex_segment[v] = segment;
    model.vertex_leaf[v] = -1;
  }
}

// Writes triangle (a, b, c) at out => the slot after it.
uint32_t* write_triangle(uint32_t a, uint32_t b, uint32_t c, uint32_t* out) {
  out[0] = a;
  out[1] = b;
  out[2] = c;
  return out + 3;
}

// Two triangles per side between rings a (lower) and b (upper), outward facing.
uint32_t* write_tube(uint32_t a, uint32_t b, uint32_t sides, uint32_t* out) {
  for (uint32_t k = 0; k < sides; ++k) {
    const uint32_t k1 = (k + 1) % sides;
    out = write_triangle(a + k, a + k1, b + k1, out);
    out = write_triangle(a + k, b + k1, b + k, out);
  }
  return out;
}

// Fan closing ring a with the centre vertex, facing along the ring tangent.
uint32_t* write_cap(uint32_t a, uint32_t centre, uint32_t sides, uint32_t* out) {
  for (uint32_t k = 0; k < sides; ++k) out = write_triangle(a + k, a + (k + 1) % sides, centre, out);
  return out;
}

}  // namespace

size_t branch_vertex_count(const SegmentTopology& topology, int ring_sides) {
  size_t n = 0;
  for (size_t s = 0; s < topology.continuation.size(); ++s)
    n += size_t(ring_sides) * (1 + topology.starts_axis[s]) + (topology.continuation[s] < 0);
  return n;
}

size_t branch_triangle_count(const SegmentTopology& topology, int ring_sides) {
  size_t n = 0;
  for (int32_t c : topology.continuation) n += size_t(ring_sides) * (c < 0 ? 3 : 2);
  return n;
}

BranchRings build_branch_mesh(const Skeleton& skeleton, const SegmentTopology& topology,
                              const TreeOptions& options, TreeModel& model) {
  const size_t S = skeleton.segment_count();
  const uint32_t sides = uint32_t(options.ring_sides);
  const RingAngles angles(options.ring_sides);
  BranchRings rings;
  rings.base_ring.resize(S);
  rings.top_ring.resize(S);
  rings.tip_vertex.assign(S, -1);
  std::vector<Ring> top(S);  // the ring at each segment's end, which its continuation starts from
  uint32_t next = 0;
  const bool surface = model.uvs.cols() != 0;
  uint32_t* tri = model.triangles.data();
  for (size_t s = 0; s < S; ++s) {
    const int32_t seg = int32_t(s);
    const Eigen::Vector3d& d = topology.direction[s];
    Ring base;
    if (topology.starts_axis[s]) {
      base.centre = skeleton.segment_start[s] * options.scale;
      base.tangent = d;
      base.normal = perpendicular(skeleton.segment_up[s], d);
      base.bend.setZero();
      base.radius = model.segment_radius_base[s];
      rings.base_ring[s] = next;
      write_ring(base, angles, next, seg, surface, model);
      next += sides;
    } else {
      const int32_t p = skeleton.segment_parent[s];
      base = top[p];
      rings.base_ring[s] = rings.top_ring[p];
    }
    Ring& end = top[s];
    end.centre = skeleton.segment_end[s] * options.scale;
    const int32_t c = topology.continuation[s];
    if (c >= 0) {
      set_joint(end, d, topology.direction[c]);
    } else {
      end.tangent = d;
      end.bend.setZero();
      end.stretch = 1.0;
    }
    end.normal = transport(base.normal, base.tangent, end.tangent);
    end.radius = model.segment_radius_top[s];
    end.v = base.v + topology.length[s];
    rings.top_ring[s] = next;
    write_ring(end, angles, next, seg, surface, model);
    next += sides;
    if (surface) tri = write_tube(rings.base_ring[s], rings.top_ring[s], sides, tri);
    if (c < 0) {
      rings.tip_vertex[s] = int32_t(next);
      model.rest_positions.col(next) = end.centre;
      if (surface) {
        model.uvs.col(next) = Eigen::Vector2f(0.5f, float(end.v));
        tri = write_cap(rings.top_ring[s], next, sides, tri);
      }
      model.vertex_segment[next] = seg;
      model.vertex_leaf[next] = -1;
      ++next;
    }
  }
  return rings;
}

}  // namespace treeanim
