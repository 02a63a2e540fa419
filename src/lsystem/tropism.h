#pragma once
// cpfg's tropisms and torques (CPFG manual 6.8, 8.1.8) and its older single tropism (8.1.10):
// the turns they give the turtle's frame around a move. The frame is treeanim's (U = H x L,
// docs/turtle.md); cpfg's up vector is -U, so "U toward X" here is cpfg's "up away from X".
#include <Eigen/Core>
#include <span>

namespace treeanim {

// A view file's "tropism:" or "torque:" line; both kinds share the ids 1, 2, ... of @Ts/@Ti/@Td
// in file order.
struct Movement {
  bool torque = false;                  // "torque:" rolls U about H; "tropism:" bends H
  Eigen::Vector3d direction{0, 1, 0};   // T: / |T:| times cpfg's intensity factor clamp(I: / |T:|, -1, 1)
  double cos_angle = 1.0;               // cos of A: (the angle to T that headings seek); 1 for a torque
  double sin_angle = 0.0;               // sin of A:; 0 for a torque
  double elasticity = 0.0;              // E: at the start of the word
  double step = 0.0;                    // S: what @Ti(id) / @Td(id) (no value) add or subtract
};

// The turtle's frame and the one it had after its last F or G (cpfg keeps U from twisting
// against that one when a tropism turns H).
struct BendFrame {
  Eigen::Vector3d& heading;       // H
  Eigen::Vector3d& left;          // L
  Eigen::Vector3d& up;            // U
  Eigen::Vector3d& last_heading;  // H after the last F or G
  Eigen::Vector3d& last_up;       // U after the last F or G
};

// movements, their current elasticities (same order), frame => the frame turned as cpfg turns it
// before every F G f g: H toward V = sum of e (cos A T + sin A P) over the tropisms (P: the unit
// vector at right angles to T toward H) about H x V by min(|H x V|, 1) radians, U carried from
// the last segment by the smallest rotation taking its H to the new one; then U rolled about H
// toward the torques' sum W = sum of e T (projected across H, times |W|) by min(|U x W'|, 1),
// after which the frame counts as the last segment's.
void apply_movements(std::span<const Movement> movements, std::span<const double> elasticity, const BendFrame& f);

// @Tp: U carried from the last segment's frame to the current H by the smallest rotation (when H
// has turned), L = U x H.
void carry_up(const BendFrame& f);

// cpfg's older tropism (8.1.10), after every F G f g: H turned toward U by asin(e T.U), then
// toward L by asin(e T.L) (T the unit "tropism direction:", the sines clamped to [-1, 1]).
void bend_old_style(const Eigen::Vector3d& direction, double elasticity, const BendFrame& f);

}  // namespace treeanim
