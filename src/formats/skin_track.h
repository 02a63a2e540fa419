#pragma once
// The keys of a skinned output (docs/outputs.md "Skinned glTF"): per written frame, each joint's
// transform relative to its parent joint, fitted to the bake (formats/skin_fit.h), and the error of
// the skinned mesh against the bake. The skinned GLB and the UsdSkel layer write the same keys.
#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

#include "formats/skin_fit.h"
#include "tree/tree_model.h"

namespace treeanim {

struct SkinTrack {
  std::vector<float> translations;        // (F*J*3) m, local to the parent joint
  std::vector<float> rotations;           // (F*J*4) unit quaternions (x, y, z, w), each the short way from the last
  std::vector<float> times;               // (F) s
  std::vector<double> frame_rms_error;    // (F) m, RMS over the vertices of skinned - baked
  double squared_error = 0;               // m^2, summed over frames and vertices
  double largest_error = 0;               // m
  double squared_displacement = 0;        // m^2, baked - rest, summed over frames and vertices
  double squared_rounding = 0;            // m^2, (|rest| 2^-24)^2, the same sums: float32's rounding of a still vertex
  std::vector<RigidMotion> motions;       // (J) scratch: the last frame's fitted motions
  std::vector<Eigen::Quaterniond> previous_rotation;  // (J) the last keys, for sign continuity
};

// One baked frame (V*3 float positions at `time` s) => its keys and errors appended to `track`.
// The joints' motions are fitted to the positions, or, given `cluster_motions` (FrameData's, the
// solver's own) and a joint per cluster, taken from them: the mesh of a bake on samples was
// placed from these, so the skin reproduces it to float rounding.
void add_skin_frame(const Skin& skin, const TreeModel& model, const float* positions,
                    const std::vector<float>& cluster_motions, double time, SkinTrack& track);

// How far the skinned mesh strays from the bake over every frame of a track.
struct SkinError {
  double rms_displacement = 0;  // m, RMS of baked - rest
  double rms_error = 0;         // m, RMS of skinned - baked
  double relative_rms = 0;      // rms_error / rms_displacement (0 when still)
  double relative_max = 0;      // largest error / rms_displacement
  double largest_error = 0;     // m
  bool still = false;           // no displacement past float32's rounding of the rest pose: no ratio means anything
};
SkinError skin_error(const SkinTrack& track, size_t vertex_count);

// The run's summary line: "skinning error RMS 1.23 %, max 4.56 % of the RMS displacement, 12 joints"
// (of a tree that never moves, the errors in m).
std::string skin_error_report(const SkinError& error, size_t joints);

}  // namespace treeanim
