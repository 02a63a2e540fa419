#include "formats/skin_track.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace treeanim {

namespace {

// Joint j's transform relative to its parent's: world_j = M_j T(pivot_j), local = world_parent^-1 world_j.
std::pair<Eigen::Matrix3d, Eigen::Vector3d> local_transform(const Skin& skin, const std::vector<RigidMotion>& motions,
                                                            size_t j) {
  const RigidMotion& m = motions[j];
  const Eigen::Vector3d& pivot = skin.joint_pivot[j];
  const int32_t parent = skin.joint_parent[j];
  if (parent < 0) return {m.rotation, m.rotation * pivot + m.translation};
  const RigidMotion& p = motions[size_t(parent)];
  const Eigen::Matrix3d rotation = p.rotation.transpose() * m.rotation;
  return {rotation, rotation * pivot + p.rotation.transpose() * (m.translation - p.translation) -
                        skin.joint_pivot[size_t(parent)]};
}

}  // namespace

void add_skin_frame(const Skin& skin, const TreeModel& model, const float* positions,
                    const std::vector<float>& cluster_motions, double time, SkinTrack& track) {
  track.previous_rotation.resize(skin.joint_count(), Eigen::Quaterniond::Identity());
  const size_t J = skin.joint_count();
  if (J == model.cluster_count() && cluster_motions.size() == 7 * J) {
    track.motions.resize(J);
    for (size_t j = 0; j < J; ++j) {
      const float* m = &cluster_motions[7 * j];
      track.motions[j].rotation = Eigen::Quaterniond(m[3], m[0], m[1], m[2]).normalized().toRotationMatrix();
      track.motions[j].translation = Eigen::Vector3d(m[4], m[5], m[6]);
    }
  } else {
    fit_joints(skin, model, positions, track.motions);
  }
  for (size_t j = 0; j < skin.joint_count(); ++j) {
    const auto [rotation, translation] = local_transform(skin, track.motions, j);
    Eigen::Quaterniond q(rotation);
    q.normalize();
    if (q.dot(track.previous_rotation[j]) < 0) q.coeffs() = -q.coeffs();  // keys interpolate the short way
    track.previous_rotation[j] = q;
    for (int a = 0; a < 3; ++a) track.translations.push_back(float(translation[a]));
    for (double c : {q.x(), q.y(), q.z(), q.w()}) track.rotations.push_back(float(c));
  }
  double frame_squared_error = 0;
  for (size_t v = 0; v < model.vertex_count(); ++v) {
    const Eigen::Vector3d baked(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
    const double error = (skinned_position(skin, model, track.motions, v) - baked).norm();
    frame_squared_error += error * error;
    track.largest_error = std::max(track.largest_error, error);
    track.squared_displacement += (baked - model.rest_positions.col(long(v))).squaredNorm();
    track.squared_rounding += model.rest_positions.col(long(v)).squaredNorm() * 0x1p-48;
  }
  track.squared_error += frame_squared_error;
  track.frame_rms_error.push_back(model.vertex_count() ? std::sqrt(frame_squared_error / double(model.vertex_count()))
                                                       : 0.0);
  track.times.push_back(float(time));
}

SkinError skin_error(const SkinTrack& track, size_t vertex_count) {
  SkinError error;
  const double samples = double(track.times.size()) * double(vertex_count);
  error.rms_displacement = samples > 0 ? std::sqrt(track.squared_displacement / samples) : 0.0;
  error.rms_error = samples > 0 ? std::sqrt(track.squared_error / samples) : 0.0;
  error.largest_error = track.largest_error;
  error.still = track.squared_displacement <= 4 * track.squared_rounding;
  error.relative_rms = error.still ? 0.0 : error.rms_error / error.rms_displacement;
  error.relative_max = error.still ? 0.0 : track.largest_error / error.rms_displacement;
  return error;
}

std::string skin_error_report(const SkinError& error, size_t joints) {
  char text[200];
  if (error.still)
    std::snprintf(text, sizeof text, "skinning error RMS %.3g m, max %.3g m, %zu joints (the tree rests in every frame)",
                  error.rms_error, error.largest_error, joints);
  else
    std::snprintf(text, sizeof text, "skinning error RMS %.2f %%, max %.2f %% of the RMS displacement, %zu joints",
                  100 * error.relative_rms, 100 * error.relative_max, joints);
  return text;
}

}  // namespace treeanim
