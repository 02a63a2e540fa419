// The 3D turtle (lpfg conventions, docs/turtle.md): module string => Skeleton.
//
// One pass over the word with the turtle state in locals: no allocation per module (the
// skeleton is reserved from symbol counts, the bracket stack grows to the deepest nesting
// once), and the sin/cos of turn angles come from a small cache because grammars reuse a
// handful of angles. Rotation signs are lpfg's "corrected rotation" ones, pinned by the
// golden tests: + turns H toward L, & pitches H toward -U, \ rolls L toward -U.
#include "lsystem/turtle.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>
#include <span>
#include <utility>
#include <vector>

namespace treeanim {
namespace {

using Eigen::Vector3d;

constexpr double kDegToRad = std::numbers::pi / 180.0;
// |V x H| below this means H is vertical: every L is then already horizontal, so '$' keeps it.
constexpr double kVerticalTolerance = 1e-12;
// |H x T| below this means H is parallel to T: no bending torque.
constexpr double kTropismTolerance = 1e-12;
// Material indices are clamped to [0, kMaxMaterial] so that any parameter converts safely.
constexpr double kMaxMaterial = 1e6;

// Everything '[' saves and ']' restores.
struct State {
  Vector3d position{0, 0, 0};
  Vector3d heading{0, 1, 0};  // H
  Vector3d left{-1, 0, 0};    // L
  Vector3d up{0, 0, 1};       // U = H x L
  double width = std::numeric_limits<double>::quiet_NaN();  // diameter, scene units
  int32_t material = 0;
  int32_t segment = -1;   // last segment drawn on this path: the parent of the next one
  bool branched = false;  // a '[' was opened since `segment` was drawn
  bool cylinder = false;  // inside a generalised cylinder (@Gs ... @Ge): 'f' draws too
  double scale = 1.0;     // cpfg's turtle scale (sub-L-system calls, @D): lengths, widths, surfaces
  Vector3d last_heading{0, 1, 0};  // H after the last F or G (cpfg's tropisms keep U from twisting against it)
  Vector3d last_up{0, 0, 1};       // U after the last F or G
  double elasticity = 0.0;         // of cpfg's older tropism, changed by '_'
};

// A '{' not yet closed: the turtle state at the '{' (the leaf's base and frame) and where its
// outline starts in the shared vertex buffer (nested polygons stack their vertices there).
struct OpenPolygon {
  State at_open;
  size_t first_point = 0;
};

struct SinCos {
  double c = 1.0;
  double s = 0.0;
};

// angle (degrees) => cos, sin; 16 direct-mapped entries keyed by the angle's bits.
class SinCosCache {
 public:
  SinCos get(double degrees) {
    const uint64_t bits = std::bit_cast<uint64_t>(degrees);
    Entry& e = entries_[(bits * 0x9E3779B97F4A7C15ull) >> 60];
    if (e.bits != bits) e = {bits, {std::cos(degrees * kDegToRad), std::sin(degrees * kDegToRad)}};
    return e.value;
  }

 private:
  struct Entry {
    uint64_t bits = 0;  // +0.0 degrees, whose value {1, 0} is the default below
    SinCos value;
  };
  std::array<Entry, 16> entries_{};
};

// Rotates the orthonormal pair (a, b) in its plane by the angle (c, s): a' = c a + s b, b' = c b - s a.
inline void rotate_pair(Vector3d& a, Vector3d& b, SinCos r) {
  const Vector3d a0 = a;
  a = r.c * a0 + r.s * b;
  b = r.c * b - r.s * a0;
}

// v, unit axis k, angle (c, s) => v rotated right-handedly about k (Rodrigues).
inline Vector3d rotate_about(const Vector3d& v, const Vector3d& k, SinCos r) {
  return r.c * v + r.s * k.cross(v) + ((1.0 - r.c) * k.dot(v)) * k;
}

// frame => the nearest orthonormal right-handed frame keeping H's direction (rounding drift).
inline void orthonormalise(State& t) {
  t.heading.normalize();
  t.left = (t.left - t.left.dot(t.heading) * t.heading).normalized();
  t.up = t.heading.cross(t.left);
}

// '$' (ABOP p.57): L = V x H / |V x H| with V = (0,1,0) opposite to gravity, U = H x L.
inline void roll_to_horizontal(State& t) {
  const Vector3d left = Vector3d(0, 1, 0).cross(t.heading);
  const double norm = left.norm();
  if (norm < kVerticalTolerance) return;
  t.left = left / norm;
  t.up = t.heading.cross(t.left);
}

// Tropism after a drawn segment (ABOP p.58): rotate the frame about H x T by e |H x T|.
inline void bend_toward(State& t, const Vector3d& tropism, double elasticity) {
  const Vector3d axis = t.heading.cross(tropism);
  const double norm = axis.norm();
  if (norm < kTropismTolerance) return;
  const Vector3d k = axis / norm;
  const double angle = elasticity * norm;
  const SinCos r{std::cos(angle), std::sin(angle)};
  t.heading = rotate_about(t.heading, k, r);
  t.left = rotate_about(t.left, k, r);
  orthonormalise(t);
}

// parameter p => material index, rounded and clamped to [0, kMaxMaterial] (NaN => 0).
inline int32_t material_index(double p) {
  if (!(p > 0.0)) return 0;
  return static_cast<int32_t>(std::lround(std::min(p, kMaxMaterial)));
}

// symbols, index of a '%' => index of the ']' closing its branch (or the word's size).
size_t end_of_branch(const std::vector<char>& symbols, size_t cut) {
  int depth = 0;
  for (size_t j = cut + 1; j < symbols.size(); ++j) {
    if (symbols[j] == '[') {
      ++depth;
    } else if (symbols[j] == ']') {
      if (depth == 0) return j;
      --depth;
    }
  }
  return symbols.size();
}

class Turtle {
 public:
  // answers: word's parameters, written by the query modules (null: only drawing).
  Turtle(const ModuleString& word, const TurtleSettings& settings, double* answers = nullptr)
      : word_(word),
        answers_(answers),
        settings_(settings),
        default_turn_{std::cos(settings.angle_degrees * kDegToRad),
                      std::sin(settings.angle_degrees * kDegToRad)},
        bends_(settings.tropism_elasticity != 0.0),
        moves_(!settings.movements.empty()) {
    for (const Movement& m : settings.movements) elasticity_.push_back(m.elasticity);
    s_.elasticity = settings.initial_elasticity;
    s_.scale = settings.initial_scale;
    reserve_outputs();
  }

  // word => skeleton: one switch per module.
  Skeleton run() {
    const std::vector<char>& symbols = word_.symbols;
    const size_t n = symbols.size();
    for (size_t i = 0; i < n; ++i) {
      switch (symbols[i]) {
        case 'F': forward(i, /*draws=*/true, /*records=*/true); break;
        case 'G': forward(i, /*draws=*/true, /*records=*/false); break;
        case 'f': forward(i, /*draws=*/false, /*records=*/true); break;
        case 'g': forward(i, /*draws=*/false, /*records=*/false); break;
        case '+': rotate_pair(s_.heading, s_.left, turn(i, 1.0)); break;
        case '-': rotate_pair(s_.heading, s_.left, turn(i, -1.0)); break;
        case '&': rotate_pair(s_.up, s_.heading, turn(i, 1.0)); break;
        case '^': rotate_pair(s_.up, s_.heading, turn(i, -1.0)); break;
        case '\\': rotate_pair(s_.up, s_.left, turn(i, 1.0)); break;
        case '/': rotate_pair(s_.up, s_.left, turn(i, -1.0)); break;
        case '|':
          s_.heading = -s_.heading;
          s_.left = -s_.left;
          break;
        case '$':
          if (settings_.calls) return_from_call();
          else roll_to_horizontal(s_);
          break;
        case '[':
          stack_.push_back(s_);
          saved_elasticity_.insert(saved_elasticity_.end(), elasticity_.begin(), elasticity_.end());
          s_.branched = true;
          break;
        case ']':
          if (!stack_.empty()) {
            s_ = stack_.back();
            stack_.pop_back();
            std::copy(saved_elasticity_.end() - static_cast<std::ptrdiff_t>(elasticity_.size()), saved_elasticity_.end(),
                      elasticity_.begin());
            saved_elasticity_.resize(saved_elasticity_.size() - elasticity_.size());
          }
          break;
        case '!':
          if (has_param(i)) s_.width = first_param(i) * s_.scale;
          else if (settings_.width_increment) s_.width = std::max(s_.width - *settings_.width_increment * s_.scale, 0.0);
          else s_.width *= settings_.width_factor;
          break;
        case '#':
          s_.width = has_param(i) ? first_param(i) * s_.scale : s_.width + settings_.width_increment.value_or(1.0) * s_.scale;
          break;
        case '\'':
        case ';': s_.material = has_param(i) ? material_index(first_param(i)) : s_.material + 1; break;
        case ',':
          s_.material = has_param(i) ? material_index(first_param(i)) : std::max(s_.material - 1, 0);
          break;
        case 'L': add_leaf(s_, has_param(i) ? first_param(i) : 1.0, {}); break;
        case '~': i = surface(i); break;
        case '@': i = at_command(i); break;
        case '?': i = settings_.calls && has_param(i) ? call(i) : query(i); break;
        case '{': polygons_.push_back({s_, points_.size()}); break;
        case '.':
          if (!polygons_.empty()) points_.push_back(s_.position);
          break;
        case '}': close_polygon(); break;
        case '%': i = end_of_branch(symbols, i) - 1; break;  // the loop's ++i lands on the ']'
        case '_': s_.elasticity = has_param(i) ? first_param(i) : s_.elasticity + settings_.elasticity_increment; break;
        default: break;  // structural module (A, B, X ...): nothing to draw
      }
    }
    return std::move(out_);
  }

 private:
  bool has_param(size_t i) const { return word_.param_offsets[i] != word_.param_offsets[i + 1]; }
  double first_param(size_t i) const { return word_.params[word_.param_offsets[i]]; }

  // '~' at i: a leaf. cpfg writes a predefined surface as '~' and its id letter ("~l(s)" or
  // "~l(sx,sy,sz)", two modules here, the parameters on the letter): the view file's surface of
  // that letter, else a leaf of the default shape scaled by s. => the last module used.
  size_t surface(size_t i) {
    const size_t n = word_.size();
    if (!has_param(i) && i + 1 < n && std::isalpha(static_cast<unsigned char>(word_.symbols[i + 1]))) {
      const std::span<const double> p = word_.params_of(i + 1);
      const auto& shapes = settings_.surfaces;
      const auto shape = std::find_if(shapes.begin(), shapes.end(), [&](const LeafShape& v) { return v.id == word_.symbols[i + 1]; });
      if (shape == shapes.end()) add_leaf(s_, (p.empty() ? 1.0 : p[0]) * s_.scale, {});
      else draw_surface(*shape, p);
      return i + 1;
    }
    add_leaf(s_, (has_param(i) ? first_param(i) : 1.0) * s_.scale, {});
    return i;
  }

  // A view-file surface scaled by p (none: 1; one: uniform; three: along -L, H, U) and by the
  // open sub-L-system calls, then the turtle moves to its end point (CPFG manual 6.7.1). A zero
  // scale draws nothing, as in cpfg.
  void draw_surface(const LeafShape& shape, std::span<const double> p) {
    const Vector3d scale =
        (p.empty() ? Vector3d(1, 1, 1) : p.size() < 3 ? Vector3d(p[0], p[0], p[0]) : Vector3d(p[0], p[1], p[2])) * s_.scale;
    const double volume = scale.prod();
    if (!(volume != 0.0) || !std::isfinite(volume)) return;
    add_shape_leaf(s_, shape, scale);
    s_.position += leaf_vector(s_, shape.end.cwiseProduct(scale));
  }

  // A sphere (@O) or circle (@o, @c) of diameter d: a small leaf of that shape on the current
  // segment. Without a parameter (the line width) it rounds a joint or a tip, which the branch
  // mesh closes already, and is left out (docs/turtle.md).
  void draw_organ(const LeafShape& shape, std::span<const double> p) {
    if (!p.empty() && p[0] > 0 && std::isfinite(p[0])) add_shape_leaf(s_, shape, Vector3d::Constant(p[0] * s_.scale));
  }

  // '?(label, s)' calls a sub-L-system (CPFG manual 7.2): lengths, widths and surfaces are
  // scaled by s (1 when not given) until its '$'. => the module used.
  // As in cpfg, a call's scale multiplies the caller's call scale, not an @D scale set since.
  size_t call(size_t i) {
    const std::span<const double> p = word_.params_of(i);
    const double s = p.size() >= 2 ? p[1] : 1.0;
    calls_.push_back(call_scale() * s);
    s_.scale = calls_.back();
    s_.width *= s;
    return i;
  }

  // '$' ends the innermost call: the turtle takes the caller's call scale and the width follows
  // (a '$' without a call changes nothing).
  void return_from_call() {
    if (calls_.empty()) return;
    const double ended = calls_.back();
    calls_.pop_back();
    s_.scale = call_scale();
    if (ended != 0.0) s_.width *= s_.scale / ended;
  }

  // The innermost open call's scale, else the view file's initial scale.
  double call_scale() const { return calls_.empty() ? settings_.initial_scale : calls_.back(); }

  // '?' and its letter (cpfg's query modules, CPFG manual 6.9): ?P ?H ?U ?L take the turtle's
  // position, heading, up and left vectors (x, y[, z]) when answering; they draw nothing.
  // => the last module used.
  size_t query(size_t i) {
    if (i + 1 >= word_.size() || has_param(i)) return i;
    const Vector3d* v = nullptr;
    switch (word_.symbols[i + 1]) {
      case 'P': v = &s_.position; break;
      case 'H': v = &s_.heading; break;
      case 'U': v = &s_.up; break;
      case 'L': v = &s_.left; break;
      default: return i;
    }
    if (answers_) {
      const uint32_t b = word_.param_offsets[i + 1], e = word_.param_offsets[i + 2];
      for (uint32_t k = b; k < e && k - b < 3; ++k) answers_[k] = stored_parameter((*v)[static_cast<Eigen::Index>(k - b)]);
    }
    return i + 1;
  }

  // '@' and the letter after it (cpfg's two-character modules, CPFG manual 6): @v rolls L
  // horizontal, @M(x,y[,z]) moves to a point, @R(hx,hy[,hz[,ux,uy,uz]]) sets the heading, @O(d) (a
  // sphere) and @o(d) @c(d) (circles) become small leaves, @Gs ... @Ge (a generalised cylinder)
  // makes 'f' draw; @T* set tropisms (tropism_module), @D* the scale (scale_module); textures
  // (@Tx), @Gc and the rest draw nothing. => the last module used.
  size_t at_command(size_t i) {
    if (i + 1 >= word_.size()) return i;
    const size_t c = i + 1;
    const std::span<const double> p = word_.params_of(c);
    switch (word_.symbols[c]) {
      case 'v': roll_to_horizontal(s_); break;
      case 'G':  // @Gs starts a generalised cylinder, @Ge ends it (read from the next module)
        if (c + 1 < word_.size() && (word_.symbols[c + 1] == 's' || word_.symbols[c + 1] == 'e')) {
          s_.cylinder = word_.symbols[c + 1] == 's';
          return c + 1;
        }
        break;
      case 'T': return tropism_module(c);
      case 'D': return scale_module(c);
      case 'O': draw_organ(sphere_shape(), p); break;
      case 'o':  // a circle in the screen's plane: a baked tree has no screen, so it lies in HL as @c
      case 'c': draw_organ(disc_shape(), p); break;
      // Two or more numbers, z 0 when two are given; a heading of zero is +Y (cpfg's blackbox.c).
      case 'M':
        if (p.size() >= 2) s_.position = Vector3d(p[0], p[1], p.size() >= 3 ? p[2] : 0.0);
        break;
      case 'R':
        if (p.size() >= 2) {
          const Vector3d h(p[0], p[1], p.size() >= 3 ? p[2] : 0.0);
          set_heading(h.norm() > 0 ? h : Vector3d::UnitY(), p);
        }
        break;
      default: break;
    }
    return c;
  }

  // @T and its subfunction at c + 1 (CPFG manual 6.8, as cpfg reads them): @Ts(id, e) sets
  // movement id's elasticity (no e: 0), @Ti(id, d) adds d and @Td(id, d) subtracts it (no d: the
  // line's S:), @Tp carries U from the last segment, @Tf makes this frame the last segment's,
  // @Tx is a texture. Without any parameter, or with an id that names no line, @Ts/@Ti/@Td do
  // nothing (cpfg warns); @T with its own parameters reads no subfunction and does nothing.
  // => the last module used.
  size_t tropism_module(size_t c) {
    if (has_param(c) || c + 1 >= word_.size()) return c;
    const std::span<const double> p = word_.params_of(c + 1);
    const char sub = word_.symbols[c + 1];
    switch (sub) {
      case 'x': break;
      case 'p': carry_up(frame()); break;
      case 'f':
        s_.last_heading = s_.heading;
        s_.last_up = s_.up;
        break;
      case 's':
      case 'i':
      case 'd': {
        const double id = p.empty() ? 0.0 : std::trunc(p[0] - 1.0);
        if (p.empty() || !(id >= 0.0 && id < static_cast<double>(elasticity_.size()))) break;
        double& e = elasticity_[static_cast<size_t>(id)];
        const double value = p.size() >= 2 ? p[1] : sub == 's' ? 0.0 : settings_.movements[static_cast<size_t>(id)].step;
        e = sub == 's' ? value : sub == 'i' ? e + value : e - value;
        break;
      }
      default: return c;  // cpfg reads an unknown subfunction as a module of its own
    }
    return c + 1;
  }

  // @D(s) sets the turtle scale to s; @Di(x) multiplies it by x and @Dd(x) divides it (no x: the
  // view file's scale multiplier; x = 0 changes nothing), as cpfg does (CPFG manual 6.3).
  // => the last module used.
  size_t scale_module(size_t c) {
    if (has_param(c)) {
      s_.scale = first_param(c);
      return c;
    }
    if (c + 1 >= word_.size() || (word_.symbols[c + 1] != 'i' && word_.symbols[c + 1] != 'd')) return c;
    const double x = has_param(c + 1) ? first_param(c + 1) : settings_.scale_multiplier;
    if (x != 0.0) s_.scale = word_.symbols[c + 1] == 'i' ? s_.scale * x : s_.scale / x;
    return c + 1;
  }

  // The turtle's frame for the tropisms.
  BendFrame frame() { return {s_.heading, s_.left, s_.up, s_.last_heading, s_.last_up}; }

  // @R: heading h, and up from p[3..5] when given (else the nearest frame to the old one).
  void set_heading(const Vector3d& h, std::span<const double> p) {
    s_.heading = h.normalized();
    const Vector3d up = p.size() >= 6 ? Vector3d(p[3], p[4], p[5]) : s_.up;
    Vector3d left = up.cross(s_.heading);
    if (left.norm() < kVerticalTolerance) left = s_.left - s_.left.dot(s_.heading) * s_.heading;
    if (left.norm() < kVerticalTolerance) return;
    s_.left = left.normalized();
    s_.up = s_.heading.cross(s_.left);
  }

  // module i, sign => cos/sin of its turn angle (its parameter, else the default δ).
  SinCos turn(size_t i, double sign) {
    const SinCos r = has_param(i) ? angles_.get(first_param(i)) : default_turn_;
    return {r.c, sign * r.s};
  }

  // F G f g at module i. Inside '{ }' they only move (F and f recording a vertex, ABOP ch. 5);
  // outside, F and G draw a segment and f and g move.
  // cpfg's tropisms turn the turtle before all four moves and its older tropism after them.
  void forward(size_t i, bool draws, bool records) {
    const double length = (has_param(i) ? first_param(i) : settings_.step) * s_.scale;
    if (moves_) apply_movements(settings_.movements, elasticity_, frame());
    if (!polygons_.empty()) {
      s_.position += length * s_.heading;
      if (records) points_.push_back(s_.position);
    } else if (draws || s_.cylinder) {
      draw_segment(static_cast<uint32_t>(i), length);
    } else {
      s_.position += length * s_.heading;
    }
    if (s_.elasticity != 0.0) bend_old_style(settings_.old_tropism, s_.elasticity, frame());
    if (moves_ && draws) {
      s_.last_heading = s_.heading;
      s_.last_up = s_.up;
    }
  }

  // module index, length => one segment appended (parents precede children), then tropism.
  void draw_segment(uint32_t module, double length) {
    Skeleton& k = out_;
    const int32_t parent = s_.segment;
    const bool continues = parent >= 0 && !s_.branched && s_.position == k.segment_end[parent];
    const int32_t order = parent < 0 ? 0 : k.segment_order[parent] + (s_.branched ? 1 : 0);
    k.segment_start.push_back(s_.position);
    s_.position += length * s_.heading;
    k.segment_end.push_back(s_.position);
    k.segment_up.push_back(s_.up);
    k.segment_width.push_back(s_.width);
    k.segment_parent.push_back(parent);
    k.segment_continues_parent.push_back(continues ? 1 : 0);
    k.segment_order.push_back(order);
    k.segment_id.push_back(module);
    k.segment_material.push_back(s_.material);
    s_.segment = static_cast<int32_t>(k.segment_start.size() - 1);
    s_.branched = false;
    if (bends_) bend_toward(s_, settings_.tropism, settings_.tropism_elasticity);
  }

  // turtle state, scale, outline (empty: default leaf shape) => one leaf on the state's segment.
  void add_leaf(const State& at, double scale, std::span<const Vector3d> outline) {
    Skeleton& k = out_;
    add_leaf_frame(at, scale);
    k.polygon_points.insert(k.polygon_points.end(), outline.begin(), outline.end());
    close_leaf();
  }

  // turtle state, shape, scale along the leaf frame's x y z => one leaf on the state's segment:
  // the shape's points placed in the world, its triangles (wound the other way when the scale
  // mirrors it).
  void add_shape_leaf(const State& at, const LeafShape& shape, const Vector3d& scale) {
    Skeleton& k = out_;
    add_leaf_frame(at, scale.x());
    for (const Vector3d& p : shape.points) k.polygon_points.push_back(at.position + leaf_vector(at, p.cwiseProduct(scale)));
    const bool mirrored = scale.prod() < 0;
    for (size_t t = 0; t < shape.triangles.size(); t += 3)
      k.leaf_triangles.insert(k.leaf_triangles.end(), {shape.triangles[t], shape.triangles[t + (mirrored ? 2 : 1)],
                                                       shape.triangles[t + (mirrored ? 1 : 2)]});
    close_leaf();
  }

  // v in the leaf frame (+x = -L, +y = H, +z = U) => the same vector in the world.
  static Vector3d leaf_vector(const State& at, const Vector3d& v) {
    return -v.x() * at.left + v.y() * at.heading + v.z() * at.up;
  }

  // A leaf's base, frame and scale; close_leaf() ends its points and triangles.
  void add_leaf_frame(const State& at, double scale) {
    Skeleton& k = out_;
    k.leaf_segment.push_back(at.segment);
    k.leaf_position.push_back(at.position);
    k.leaf_heading.push_back(at.heading);
    k.leaf_left.push_back(at.left);
    k.leaf_up.push_back(at.up);
    k.leaf_scale.push_back(scale);
  }
  void close_leaf() {
    Skeleton& k = out_;
    k.leaf_polygon_offsets.push_back(static_cast<uint32_t>(k.polygon_points.size()));
    k.leaf_triangle_offsets.push_back(static_cast<uint32_t>(k.leaf_triangles.size()));
  }

  // '}': the innermost open polygon becomes a leaf based at its '{' if it has an area
  // (>= 3 vertices; fewer would read as "default leaf shape" downstream, so they are dropped).
  void close_polygon() {
    if (polygons_.empty()) return;
    const OpenPolygon open = polygons_.back();
    polygons_.pop_back();
    const std::span<const Vector3d> outline(points_.data() + open.first_point,
                                            points_.size() - open.first_point);
    if (outline.size() >= 3) add_leaf(open.at_open, 1.0, outline);
    points_.resize(open.first_point);
  }

  // Reserves the skeleton from symbol counts (F/G bound the segments, L ~ { the leaves) and
  // starts widths at settings.initial_width when the word uses '!' (else they stay NaN).
  void reserve_outputs() {
    std::array<size_t, 256> counts{};  // of every symbol, in one pass over the word
    for (const char c : word_.symbols) ++counts[static_cast<unsigned char>(c)];
    const auto count = [&](char c) { return counts[static_cast<unsigned char>(c)]; };
    const size_t segments = count('F') + count('G');
    const size_t leaves = count('L') + count('~') + count('{') + count('@');
    if (count('!') + count('#') > 0) s_.width = settings_.initial_width;
    Skeleton& k = out_;
    k.segment_start.reserve(segments);
    k.segment_end.reserve(segments);
    k.segment_up.reserve(segments);
    k.segment_width.reserve(segments);
    k.segment_parent.reserve(segments);
    k.segment_continues_parent.reserve(segments);
    k.segment_order.reserve(segments);
    k.segment_id.reserve(segments);
    k.segment_material.reserve(segments);
    k.leaf_segment.reserve(leaves);
    k.leaf_position.reserve(leaves);
    k.leaf_heading.reserve(leaves);
    k.leaf_left.reserve(leaves);
    k.leaf_up.reserve(leaves);
    k.leaf_scale.reserve(leaves);
    k.leaf_polygon_offsets.reserve(leaves + 1);
    k.leaf_polygon_offsets.push_back(0);
    k.leaf_triangle_offsets.reserve(leaves + 1);
    k.leaf_triangle_offsets.push_back(0);
  }

  const ModuleString& word_;
  double* const answers_;  // word_'s parameters, when answering queries
  const TurtleSettings& settings_;
  const SinCos default_turn_;  // cos, sin of settings.angle_degrees
  const bool bends_;           // tropism on
  const bool moves_;           // cpfg tropisms or torques given
  State s_;
  std::vector<State> stack_;          // '[' states, innermost last
  std::vector<double> calls_;         // the scale of each open sub-L-system call, innermost last
  std::vector<double> elasticity_;    // [movements] current elasticity of each cpfg tropism and torque
  std::vector<double> saved_elasticity_;  // [open '[' x movements] elasticity_ at each open '[', innermost last
  std::vector<OpenPolygon> polygons_; // open '{', innermost last
  std::vector<Vector3d> points_;      // vertices of the open polygons, outer ones first
  SinCosCache angles_;
  Skeleton out_;
};

}  // namespace

Skeleton interpret(const ModuleString& word, const TurtleSettings& settings) {
  return Turtle(word, settings).run();
}

void answer_queries(ModuleString* word, const TurtleSettings& settings) {
  Turtle(*word, settings, word->params.data()).run();
}

}  // namespace treeanim
