#pragma once
// SimState: everything that changes during a bake (DESIGN.md; MuJoCo's mjData). Small enough
// to checkpoint; the TreeModel it belongs to is read-only. sim/ may add fields.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace treeanim {

struct SimState {
  Eigen::Matrix3Xd positions;               // (3 x V) m
  Eigen::Matrix3Xd velocities;              // (3 x V) m/s
  std::vector<uint8_t> leaf_attached;       // (L) 1 while the leaf hangs on its branch
  double time = 0;                          // s
  Eigen::Matrix4Xd cluster_rotations;       // (4 x C) unit quaternions (x, y, z, w), warm starts
  std::vector<uint8_t> island_asleep;       // (I) 1: the island rests at its rest pose, no work
  // Nonzero: the simulator that wrote this state already holds the prediction of its next
  // step (computed with the last correction). Set it to 0 after changing positions or
  // velocities by hand, so the next frame predicts from them.
  uint64_t prediction_stamp = 0;
};

}  // namespace treeanim
