#pragma once
// SimState: everything that changes during a bake (docs/design.md; MuJoCo's mjData). Complete: a
// state copied or loaded into a fresh Simulator of the same model and options continues
// bit-identically (tests/sim/test_resume.cpp). The TreeModel it belongs to is read-only;
// what a detachment changes in the clusters' rest data is a function of the model and
// `leaf_attached`, rebuilt from them (docs/solver.md, "Leaves").
#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace treeanim {

// The prediction of the next step (docs/solver.md, "One step"), in the solver's precision:
// the last step of a frame makes it, so the next frame starts without a prediction pass.
template <typename Real>
struct StepPrediction {
  using Rows3 = Eigen::Matrix<Real, Eigen::Dynamic, 3>;  // (n x 3), a column per axis
  Rows3 offset;      // (V x 3) m, u_p = p - x0: the predicted position as a displacement from rest
  Rows3 velocity;    // (V x 3) m/s, v* of the predicted step
  Rows3 drag_force;  // (V x 3) N, the drag in that step; (0 x 3) without detaching leaves or the beam
  // (V x 3) m, the offset from rest the global term pulled toward in that step (the static
  // deflection; 0 without the beam). The next step's velocity estimate reads it.
  Rows3 goal;
  // (V x 3) m, the part of that goal the vertex's own velocity took off through its drag, c v
  // at the step's start (the chain's damping, diagonal estimate): goal + it is the deflection
  // the next step's velocity estimate extrapolates (docs/solver.md, "Aerodynamic damping").
  Rows3 damping_offset;
  // (V) s, c: how far the chain moves the vertex's goal back per m/s of the vertex's velocity
  // when its whole limb moves with it, from that step's drag (0 without the beam).
  Eigen::Matrix<Real, Eigen::Dynamic, 1> damping_compliance;
};

struct SimState {
  Eigen::Matrix3Xd positions;               // (3 x V) m
  Eigen::Matrix3Xd velocities;              // (3 x V) m/s
  std::vector<uint8_t> leaf_attached;       // (L) 1 while the leaf hangs on its branch
  double time = 0;                          // s
  Eigen::Matrix4Xd cluster_rotations;       // (4 x C) unit quaternions (x, y, z, w), warm starts
  Eigen::Matrix3Xd cluster_shift;           // (3 x C) m, t - t0 of the last fit (a flying leaf feels the air there)
  std::vector<uint8_t> island_asleep;       // (I) 1: the island rests at its rest pose, no work
  // True when the prediction below belongs to positions and velocities (the frame that wrote
  // them predicted the next step). Set it to false after changing them by hand, so the next
  // frame predicts from them.
  bool predicted = false;
  StepPrediction<double> prediction_double;  // used by a solver in hsm.precision "double"
  StepPrediction<float> prediction_float;    // used by a solver in hsm.precision "float"

  template <typename Real>
  StepPrediction<Real>& prediction() {
    if constexpr (sizeof(Real) == sizeof(float)) return prediction_float;
    else return prediction_double;
  }
  template <typename Real>
  const StepPrediction<Real>& prediction() const {
    if constexpr (sizeof(Real) == sizeof(float)) return prediction_float;
    else return prediction_double;
  }
};

}  // namespace treeanim
