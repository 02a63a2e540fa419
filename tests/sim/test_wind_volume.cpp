// A velocity volume as the wind (docs/scene.md `wind.volume`): volumes written at test time
// by the OpenVDB library itself (python3-openvdb, tests/volume/write_volumes.py) in the
// layouts Houdini and Blender write, read and sampled as the solver samples its air.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>

#include "common/errors.h"
#include "sim/grown_tree.h"
#include "sim/simulator.h"
#include "sim/solver_step.h"
#include "sim/sim_test_models.h"
#include "sim/tip_motion.h"
#include "temp_folder_test.h"

namespace treeanim {
namespace {

// A figure for RecordProperty, in three significant digits.
std::string figure(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

class WindVolumeTest : public TempFolderTest {
 protected:
  WindVolumeTest() : TempFolderTest("treeanim_volume") {}

  // write_volumes.py FLOW LAYOUT into dir_/name with `arguments` => the volume's options.
  VolumeOptions write(const std::string& flow, const std::string& layout, const std::string& name,
                      const std::string& arguments) {
    const std::filesystem::path out = dir_ / name;
    const std::string command = "/usr/bin/python3 " + std::string(TREEANIM_SOURCE_DIR) +
                                "/tests/volume/write_volumes.py " + flow + " " + layout + " " + out.string() + " " +
                                arguments;
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
    VolumeOptions volume;
    const bool blender = layout == "blender";
    volume.path = out / (blender ? "fluid_data_####.vdb" : "vel.####.vdb");
    volume.grid = blender ? "velocity" : "vel";
    volume.z_up = blender;
    return volume;
  }
};

TEST(WindVolume, FramePatternsNameTheFilesAsHoudiniAndPrintfDo) {
  EXPECT_EQ(volume_frame_path("smoke/vel.####.vdb", 7), "smoke/vel.0007.vdb");
  EXPECT_EQ(volume_frame_path("smoke/vel.####.vdb", 12345), "smoke/vel.12345.vdb");
  EXPECT_EQ(volume_frame_path("smoke/vel.####.vdb", -1), "smoke/vel.-001.vdb");
  EXPECT_EQ(volume_frame_path("cache#1/fluid_data_%04d.vdb", 3), "cache#1/fluid_data_0003.vdb");
  EXPECT_EQ(volume_frame_path("vel.%d.vdb", 42), "vel.42.vdb");
  EXPECT_EQ(volume_frame_path("still/vel.vdb", 42), "still/vel.vdb");  // one volume for all time
  VolumeOptions still;
  still.path = "still/vel.vdb";
  EXPECT_EQ(volume_frames_at(still, 12.5).first, still.first_frame);
}

// The solver's air at every cluster of `model` at time t (no flying leaf): set_air_time and
// sample_cluster_air as a step calls them.
Eigen::MatrixX3d cluster_air(const TreeModel& model, const WindOptions& wind, double t) {
  const SolverModel<double> solver(model, HsmOptions{}, wind, 1.0 / 24, 2);
  StepScratch<double> scratch(solver);
  SimState state;
  state.cluster_shift.setZero(3, solver.C);
  set_air_time(solver, t, scratch);
  for (size_t c = 0; c < solver.C; ++c) sample_cluster_air(solver, solver.all_attached, state, scratch, c);
  return scratch.cluster_air;
}

TEST_F(WindVolumeTest, AShearedVolumeGivesTheAnalyticWindAtTheAirPointsInEveryLayout) {
  // (2 + 1.5 y, 0, 0) m/s: trilinear interpolation is exact for a linear field, so what is left
  // is float32 storage (speeds up to 14 m/s: 1e-6 m/s) and the Z-up turn of Blender's layout.
  const TreeModel model = testing::small_tree(6, Eigen::Vector3d(1.3, 0, -0.7));
  double worst = 0;
  for (const std::string layout : {"houdini", "split", "blender"}) {
    SCOPED_TRACE(layout);
    WindOptions wind;
    wind.volume = write("shear", layout, layout, "--frames 1 2 --voxel 0.5");
    wind.volume->outside = VolumeOutside::kCalm;
    const Eigen::MatrixX3d air = cluster_air(model, wind, 0.5 / 24);
    const SolverModel<double> solver(model, HsmOptions{}, wind, 1.0 / 24, 2);
    for (size_t c = 0; c < solver.C; ++c) {
      const Eigen::Vector3d x = solver.all_attached.cluster_rest_centre.col(c);
      const Eigen::Vector3d expected(2 + 1.5 * x.y(), 0, 0);
      const double error = (air.row(c).transpose() - expected).norm();
      worst = std::max(worst, error);
      EXPECT_LT(error, 1e-5) << "cluster " << c << " at " << x.transpose();
    }
    // A point between voxel centres, and beyond the box: still air outside (`calm`).
    const WindField field(wind);
    EXPECT_NEAR(field.velocity(Eigen::Vector3d(0.123, 2.71, -1.9), 0).x(), 2 + 1.5 * 2.71, 1e-5);
    EXPECT_EQ(field.velocity(Eigen::Vector3d(0, 9, 0), 0), Eigen::Vector3d::Zero());
  }
  RecordProperty("largest_error_m_per_s", figure(worst));
}

TEST_F(WindVolumeTest, OutsideItTheKeysStillAirOrTheEdgeBlowAndItStandsWherePlaced) {
  // (2 + 1.5 y, 0, 0) over [-4, 4] x [0, 8] x [-4, 4]; the keys blow 3 m/s along +z.
  WindOptions wind;
  wind.keys = {{0, 3, {0, 0, 1}, 0}};
  wind.turbulence_intensity = 0;
  wind.volume = write("shear", "houdini", "shear", "--frames 1 2 --voxel 0.5");
  const Eigen::Vector3d above(0.5, 9, 0.5);
  wind.volume->outside = VolumeOutside::kKeys;
  EXPECT_TRUE(WindField(wind).velocity(above, 0).isApprox(Eigen::Vector3d(0, 0, 3)));
  wind.volume->outside = VolumeOutside::kCalm;
  EXPECT_EQ(WindField(wind).velocity(above, 0), Eigen::Vector3d::Zero());
  wind.volume->outside = VolumeOutside::kEdge;  // the top voxels' 2 + 1.5 * 8
  EXPECT_TRUE(WindField(wind).velocity(above, 0).isApprox(Eigen::Vector3d(14, 0, 0)));
  // Placed: 2 m per unit, turned 90 degrees about +Y, its origin at (10, 0, 5). The cache's
  // point p is the scene's 10, 0, 5 + R (2 p), and its velocity there is 2 R v(p).
  wind.volume->outside = VolumeOutside::kCalm;
  wind.volume->units = 2;
  wind.volume->rotate = 90;
  wind.volume->translate = Eigen::Vector3d(10, 0, 5);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d p(1, 3, -2);
  const Eigen::Vector3d x = wind.volume->translate + turn * (2 * p);
  const Eigen::Vector3d expected = 2 * (2 + 1.5 * p.y()) * (turn * Eigen::Vector3d::UnitX());
  EXPECT_LT((WindField(wind).velocity(x, 0) - expected).norm(), 1e-5) << WindField(wind).velocity(x, 0).transpose();
}

TEST_F(WindVolumeTest, LinearInTimeBetweenFramesAndAFrameMissingIsNamed) {
  // Frame k (from 1) blows 8 + (k - 1) m/s; the volume at 12 fps, the scene at 24.
  WindOptions wind;
  wind.volume = write("steps", "houdini", "steps", "--frames 1 3 --fps 12 --voxel 1");
  wind.volume->fps = 12;
  const WindField field(wind);
  const Eigen::Vector3d x(0.2, 1.7, 0.4);
  EXPECT_NEAR(field.velocity(x, 0).x(), 8, 1e-6);
  EXPECT_NEAR(field.velocity(x, 1.0 / 24).x(), 8.5, 1e-6);
  EXPECT_NEAR(field.velocity(x, 2.0 / 24).x(), 9, 1e-6);
  EXPECT_NEAR(field.velocity(x, 3.0 / 24).x(), 9.5, 1e-6);
  EXPECT_EQ(volume_frames_at(*wind.volume, 2.0 / 12).first, 3);
  EXPECT_EQ(volume_frames_at(*wind.volume, 2.0 / 12).weight, 0);  // a frame's own time reads that frame alone
  // Beyond the sequence: the frame is missing, named.
  try {
    (void)field.velocity(x, 3.0 / 12);
    FAIL() << "no error past the last frame";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("vel.0004.vdb: the volume frame is missing"), std::string::npos) << e.what();
  }
}

TEST_F(WindVolumeTest, AUniformVolumeBakesAsTheSameKeyedWind) {
  // 8 m/s along +x. 8 is exact in float32 and trilinear weights summing to 1 keep it exact, so
  // the bakes agree to the last bit; the bound 1e-9 m allows for a velocity float32 rounds
  // (6e-8 relative), which moves a tree by about that part of its sway. First the volume alone
  // against the keys alone (no gusts or turbulence: a volume without keys has none), then both
  // with the keys' gusts and turbulence on top of the volume.
  const VolumeOptions uniform = write("uniform", "houdini", "uniform", "--frames 1 49 --voxel 1 --velocity 8 0 0");
  const int frames = 48;
  for (const bool on_top : {false, true}) {
    SCOPED_TRACE(on_top ? "gusts and turbulence on top" : "the volume alone");
    WindOptions keyed;
    keyed.keys = {{0, 8, {1, 0, 0}, on_top ? 2.0 : 0.0}};
    if (!on_top) keyed.turbulence_intensity = 0;
    WindOptions volume = keyed;
    if (!on_top) volume.keys.clear();
    volume.volume = uniform;
    const std::vector<Eigen::Vector3d> a = testing::tip_motion(Eigen::Vector3d::Zero(), keyed, frames),
                                       b = testing::tip_motion(Eigen::Vector3d::Zero(), volume, frames);
    double largest = 0, sway = 0;
    for (int f = 0; f < frames; ++f) {
      largest = std::max(largest, (a[size_t(f)] - b[size_t(f)]).norm());
      sway = std::max(sway, a[size_t(f)].norm());
    }
    EXPECT_GT(sway, 0.01);  // the wind moves the tree: the comparison can fail
    EXPECT_LE(largest, 1e-9);
    RecordProperty(on_top ? "on_top_largest_difference_m" : "alone_largest_difference_m", figure(largest));
    RecordProperty(on_top ? "on_top_largest_sway_m" : "alone_largest_sway_m", figure(sway));
  }
}

TEST_F(WindVolumeTest, FlyingLeavesFeelTheVolumeWhereTheyAre) {
  // Leaves that detach sample the volume at their centres each step; held at its edge beyond
  // the box (`edge`), a uniform 20 m/s volume is the keys' 20 m/s wherever they fly.
  const TreeModel model = testing::small_tree(6);
  HsmOptions options;
  options.leaf_detach_force = 0.01;
  WindOptions keyed;
  keyed.keys = {{0, 20, {1, 0, 0}, 0}};
  keyed.turbulence_intensity = 0;
  WindOptions volume = keyed;
  volume.keys.clear();
  volume.volume = write("uniform", "houdini", "uniform", "--frames 1 25 --voxel 1 --velocity 20 0 0");
  volume.volume->outside = VolumeOutside::kEdge;
  std::vector<SimState> states;
  for (const WindOptions& wind : {keyed, volume}) {
    Simulator sim(model, options, wind, 1.0 / 24, 4);
    SimState state = sim.initial_state(0);
    for (int f = 1; f <= 24; ++f) sim.advance_frame(state, f);
    states.push_back(state);
  }
  EXPECT_NE(std::count(states[0].leaf_attached.begin(), states[0].leaf_attached.end(), 0), 0);  // leaves flew
  EXPECT_EQ(states[0].leaf_attached, states[1].leaf_attached);
  EXPECT_LE((states[0].positions - states[1].positions).cwiseAbs().maxCoeff(), 1e-9);
}

TEST_F(WindVolumeTest, AGustFrontReachesEachTreeOfAForestInTurnAndPushesItDownwind) {
  // A front of 12 m/s moving along +x at 6 m/s from x = -12 m at t = 0 through three trees at
  // x = -6, 0, 6 m: it reaches them at 1, 2 and 3 s. Still air ahead of it; the volume at 12 fps.
  WindOptions wind;
  wind.volume = write("gust", "houdini", "gust",
                      "--frames 1 49 --fps 12 --voxel 0.5 --lower -10 0 -4 --upper 10 6 4 --speed 12 "
                      "--front-start -12 --front-speed 6 --width 0.5");
  wind.volume->fps = 12;
  wind.volume->outside = VolumeOutside::kCalm;
  const int frames = 24 * 4;
  const double xs[3] = {-6, 0, 6};
  double moved_at[3];
  for (int i = 0; i < 3; ++i) {
    const std::vector<Eigen::Vector3d> motion = testing::tip_motion(Eigen::Vector3d(xs[i], 0, 0), wind, frames);
    int first = -1;
    for (int f = 0; f < frames && first < 0; ++f)
      if (motion[size_t(f)].norm() > 0.005) first = f;
    ASSERT_GE(first, 0) << "the tree at x = " << xs[i] << " never moved";
    moved_at[i] = (first + 1) / 24.0;
    EXPECT_GT(motion[size_t(first)].x(), 0.9 * motion[size_t(first)].norm()) << "not pushed along the flow";
    const double arrival = (xs[i] + 12) / 6;
    EXPECT_NEAR(moved_at[i], arrival, 0.5) << "tree at x = " << xs[i];
    RecordProperty("tree_" + std::to_string(i) + "_moves_at_s", figure(moved_at[i]));
  }
  EXPECT_LT(moved_at[0], moved_at[1]);
  EXPECT_LT(moved_at[1], moved_at[2]);
}

TEST_F(WindVolumeTest, IdenticalBytesFor1And2And4Threads) {
  // Every sample is a pure function of position and time: the same bytes at any thread count.
  const TreeModel model = testing::grown_tree(7, 2, 2);
  WindOptions wind;
  wind.volume = write("shear", "split", "shear", "--frames 1 13 --voxel 0.5 --lower -6 0 -6 --upper 6 10 6");
  std::vector<Eigen::Matrix3Xd> results;
  const int saved = omp_get_max_threads();
  for (int threads : {1, 2, 4}) {
    omp_set_num_threads(threads);
    Simulator sim(model, HsmOptions{}, wind, 1.0 / 24, 3);
    SimState state = sim.initial_state(0);
    for (int f = 1; f <= 12; ++f) sim.advance_frame(state, f);
    results.push_back(state.positions);
  }
  omp_set_num_threads(saved);
  EXPECT_GT((results[0] - model.rest_positions).cwiseAbs().maxCoeff(), 1e-4);  // the wind moved it
  EXPECT_EQ(results[0], results[1]);
  EXPECT_EQ(results[0], results[2]);
}

}  // namespace
}  // namespace treeanim
