// cpfg's tropisms and torques around a move (CPFG manual 6.8, 8.1.8, 8.1.10; the order and the
// one-radian limits as cpfg's interpreter applies them).
#include "lsystem/tropism.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace treeanim {
namespace {

using Eigen::Vector3d;

// |H x T| below this: H is along T, the tropism's own side vector is undefined (cpfg's bound).
constexpr double kParallel = 1e-7;
// |H x V| below this: no tropism turn, and U is left as it is (cpfg's bound).
constexpr double kNoTurn = 1e-6;
// |H x W|^2 below this: H is along the torques' direction, which then gives no roll (cpfg's bound).
constexpr double kNoRoll = 1e-8;

// v rotated right-handedly about the unit axis k by `angle` radians (Rodrigues).
Vector3d rotated(const Vector3d& v, const Vector3d& k, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return c * v + s * k.cross(v) + ((1.0 - c) * k.dot(v)) * k;
}

// a turned toward b about a x b by min(|a x b|, 1) radians; false when |a x b| < bound.
bool turn_toward(Vector3d& a, const Vector3d& b, double bound) {
  const Vector3d axis = a.cross(b);
  const double norm = axis.norm();
  if (norm < bound) return false;
  a = rotated(a, axis / norm, std::min(norm, 1.0));
  return true;
}

// The nearest orthonormal frame keeping H's direction (rounding drift), L = U x H.
void orthonormalise(const BendFrame& f) {
  f.heading.normalize();
  f.up = (f.up - f.up.dot(f.heading) * f.heading).normalized();
  f.left = f.up.cross(f.heading);
}

// The tropisms' target V for heading h and left vector l (l stands in for H x T when H is along T).
Vector3d tropism_target(std::span<const Movement> movements, std::span<const double> elasticity, const Vector3d& h,
                        const Vector3d& l) {
  Vector3d v = Vector3d::Zero();
  for (size_t i = 0; i < movements.size(); ++i) {
    const Movement& m = movements[i];
    if (m.torque) continue;
    v += elasticity[i] * m.cos_angle * m.direction;
    if (m.sin_angle == 0.0) continue;
    Vector3d side = h.cross(m.direction);
    double norm = side.norm();
    if (norm < kParallel) {
      side = l;
      norm = 1.0;
    }
    v += (elasticity[i] * m.sin_angle / norm) * m.direction.cross(side);
  }
  return v;
}

}  // namespace

void carry_up(const BendFrame& f) {
  const Vector3d axis = f.last_heading.cross(f.heading);
  const double norm = axis.norm();
  if (norm > kNoTurn) {
    double angle = std::asin(std::min(norm, 1.0));
    if (f.heading.dot(f.last_heading) < 0) angle = std::numbers::pi - angle;
    f.up = rotated(f.last_up, axis / norm, angle);
  }
  orthonormalise(f);
}

void apply_movements(std::span<const Movement> movements, std::span<const double> elasticity, const BendFrame& f) {
  if (turn_toward(f.heading, tropism_target(movements, elasticity, f.heading, f.left), kNoTurn)) carry_up(f);
  Vector3d twist = Vector3d::Zero();
  for (size_t i = 0; i < movements.size(); ++i)
    if (movements[i].torque) twist += elasticity[i] * movements[i].direction;
  if (twist == Vector3d::Zero()) return;
  const Vector3d across = f.heading.cross(twist.normalized());
  if (across.squaredNorm() <= kNoRoll) return;
  if (turn_toward(f.up, across.cross(f.heading) * twist.norm(), kParallel)) orthonormalise(f);
  f.last_heading = f.heading;
  f.last_up = f.up;
}

void bend_old_style(const Vector3d& direction, double elasticity, const BendFrame& f) {
  // One turn of H toward the unit vector `toward` (U, then L) by asin(e T.toward); `toward` follows.
  const auto bend = [&](Vector3d& toward) {
    const double s = std::clamp(elasticity * direction.dot(toward), -1.0, 1.0);
    const double c = std::sqrt(1.0 - s * s);
    const Vector3d h = c * f.heading + s * toward;
    toward = c * toward - s * f.heading;
    f.heading = h;
  };
  bend(f.up);
  bend(f.left);
}

}  // namespace treeanim
