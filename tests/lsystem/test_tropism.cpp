// cpfg's tropisms and torques (CPFG manual 6.8, 8.1.8), its older tropism (8.1.10) and turtle
// scale (6.3): grammars and view files written for these tests in cpfg's style, the shapes
// checked against bends computed by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "expect_near.h"
#include "lsystem/lsystem.h"
#include "temp_folder_test.h"

namespace treeanim {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;

class Tropism : public TempFolderTest {
 protected:
  Tropism() : TempFolderTest("treeanim_tropism") {}

  // A grammar of one axiom and its view file => the skeleton (options as the scene gives them).
  Skeleton grow(const std::string& axiom, const std::string& view, LsystemOptions options = {}) const {
    std::ofstream(dir_ / "plant.l") << "Lsystem: 1\nderivation length: 0\nAxiom: " << axiom << "\nendlsystem\n";
    std::ofstream(dir_ / "plant.v") << view;
    options.grammar = dir_ / "plant.l";
    options.view = dir_ / "plant.v";
    return grow_skeleton(options, nullptr);
  }

};

// The unit vector at angle a (radians) from +y toward +x.
Vector3d in_plane(double a) { return {std::sin(a), std::cos(a), 0.0}; }

// Two tropisms and a torque, switched per branch by @Ts: the bend comes before the move, is
// |H x V| radians, and each branch keeps its own elasticities.
TEST_F(Tropism, TwoTropismsAndATorqueSwitchedPerSegment) {
  const Skeleton k = grow(
      "F(1) [@Ts(1,0.5) F(1)] [&(60) @Ts(2,0.3) F(1)] [/(90) @Ts(3,0.4) F(1) @Ts(3,0) &(90) F(1)]"
      " F(1) @Ts(1,0.5) F(1) F(1) @Ts(1,0) F(1)",
      "tropism: T: 1 0 0\ntropism: T: 0 0 1 A: 90\ntorque: T: 0 0 1\n");
  ASSERT_EQ(k.segment_count(), 9u);
  expect_near(k.segment_end[0], {0, 1, 0});
  // Orthotropism toward +x with e = 0.5: H turns 0.5 |H x T| = 0.5 rad before the segment.
  expect_near(k.segment_end[1], Vector3d(0, 1, 0) + in_plane(0.5));
  // Diatropism (A: 90) to the plane across T = +z: H 60 degrees below it turns up by 0.3 sin 60.
  // The elasticities are the string's parameters, 32-bit floats.
  const double pitch = std::numbers::pi / 3 - double(0.3f) * std::sin(std::numbers::pi / 3);
  expect_near(k.segment_end[2], Vector3d(0, 1 + std::cos(pitch), -std::sin(pitch)));
  // The torque rolls U (here +x after /(90)) about H toward T = +z by 0.4 rad; H stays.
  expect_near(k.segment_end[3], {0, 2, 0});
  const double roll = double(0.4f);
  expect_near(k.segment_up[3], {std::cos(roll), 0, std::sin(roll)});
  expect_near(k.segment_end[4], Vector3d(0, 2, 0) - Vector3d(std::cos(roll), 0, std::sin(roll)));  // &(90): H = -U
  // The main axis: its elasticities were restored at each ']'.
  expect_near(k.segment_end[5], {0, 2, 0});
  const double second = 0.5 + 0.5 * std::cos(0.5);  // 0.5 |H x T| with H at 0.5 rad from +y
  expect_near(k.segment_end[6], Vector3d(0, 2, 0) + in_plane(0.5));
  expect_near(k.segment_end[7], k.segment_end[6] + in_plane(second));
  expect_near(k.segment_end[8], k.segment_end[7] + in_plane(second));  // @Ts(1,0): straight on
}

// @Ti/@Td add and subtract S: (or their value), @Ts(id) sets 0, an id of no line and a bare
// @Ts do nothing; a turn is at most one radian; f turns too.
TEST_F(Tropism, ElasticityStepsAndTheOneRadianLimit) {
  const Skeleton k = grow("@Ti(1) F(1) @Ti(1,0.25) F(1) @Td(1) F(1) @Ts(1) @Ts(9,5) @Ts F(1)",
                          "tropism: T: 1 0 0 S: 0.25\n");
  ASSERT_EQ(k.segment_count(), 4u);
  const double a1 = 0.25, a2 = a1 + 0.5 * std::cos(a1), a3 = a2 + 0.25 * std::cos(a2);
  expect_near(k.segment_end[0], in_plane(a1));
  expect_near(k.segment_end[1], k.segment_end[0] + in_plane(a2));
  expect_near(k.segment_end[2], k.segment_end[1] + in_plane(a3));
  expect_near(k.segment_end[3], k.segment_end[2] + in_plane(a3));

  const Skeleton strong = grow("f(1) F(1)", "tropism: T: 1 0 0 E: 5\n");
  ASSERT_EQ(strong.segment_count(), 1u);
  expect_near(strong.segment_start[0], in_plane(1.0));  // 5 |H x T| = 5, limited to 1 rad
  // Then 5 |H x T| = 5 cos 1 > 1: one more radian, past T as in cpfg.
  expect_near(strong.segment_end[0], in_plane(1.0) + in_plane(2.0));
}

// cpfg's older tropism bends after the move: toward U by asin(e T.U), then toward L by
// asin(e T.L); '_' sets the elasticity or adds the increment.
TEST_F(Tropism, OlderTropismBendsAfterEachMove) {
  const Skeleton k = grow("F(1) F(1) _(0) F(1) _ _ F(1) F(1)",
                          "tropism direction: 2,0,0\ninitial elasticity: 0.5\nelasticity increment: 0.25\n");
  ASSERT_EQ(k.segment_count(), 5u);
  const double a1 = std::asin(0.5), a2 = a1 + std::asin(0.5 * std::cos(a1));
  expect_near(k.segment_end[0], {0, 1, 0});
  expect_near(k.segment_end[1], k.segment_end[0] + in_plane(a1));
  expect_near(k.segment_end[2], k.segment_end[1] + in_plane(a2));
  expect_near(k.segment_end[3], k.segment_end[2] + in_plane(a2));
  expect_near(k.segment_end[4], k.segment_end[3] + in_plane(a2 + std::asin(0.5 * std::cos(a2))));
}

// The scene's tropism keys stand for the view file's first "tropism:" line (not a torque).
TEST_F(Tropism, SceneKeysReplaceTheFirstTropismLine) {
  LsystemOptions options;
  options.tropism = Vector3d(-3, 0, 0);
  options.tropism_elasticity = 0.5;
  const Skeleton k = grow("F(1)", "torque: T: 0 0 1 E: 1\ntropism: T: 0 0 1 E: 0\n", options);
  expect_near(k.segment_end[0], in_plane(-0.5));
}

// initial scale: and @D/@Di/@Dd (CPFG manual 6.3, 8.1.1) scale the lengths.
TEST_F(Tropism, TurtleScale) {
  const Skeleton k = grow("F(1) @Di F(1) @D(1) F(1) @Dd(2) F(1) @Di(0) F(1)", "initial scale: 2\nscale multiplier: 3\n");
  ASSERT_EQ(k.segment_count(), 5u);
  const double ends[] = {2.0, 8.0, 9.0, 9.5, 10.0};
  for (size_t s = 0; s < 5; ++s) expect_near(k.segment_end[s], {0, ends[s], 0});
}

}  // namespace
}  // namespace treeanim
