// Turtle interpretation (docs/turtle.md): golden positions, rotations against the analytical
// rotation, '$', tropism, brackets, parent links, leaves, polygons, '%', widths, materials.
// Words are built with ModuleString::push so these tests do not depend on the grammar parser.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include "expect_near.h"
#include "lsystem/surface_file.h"
#include "lsystem/turtle.h"

namespace treeanim {
namespace {

using Eigen::Vector3d;

constexpr double kDeg = std::numbers::pi / 180.0;

// "F(1)[+(90,2)F]" => modules: one character each, numeric parameters in parentheses.
ModuleString word(const std::string& text) {
  ModuleString w;
  w.clear();
  for (size_t i = 0; i < text.size(); ++i) {
    const char symbol = text[i];
    std::vector<double> params;
    if (i + 1 < text.size() && text[i + 1] == '(') {
      const char* p = text.c_str() + i + 2;
      while (*p != ')') {
        char* end = nullptr;
        params.push_back(std::strtod(p, &end));
        p = (*end == ',') ? end + 1 : end;
      }
      i = static_cast<size_t>(p - text.c_str());
    }
    w.push(symbol, params);
  }
  return w;
}

Skeleton draw(const std::string& text, const TurtleSettings& settings = {}) {
  return interpret(word(text), settings);
}

struct Frame {
  Vector3d h, l, u;
};

Frame leaf_frame(const Skeleton& k, size_t leaf) {
  return {k.leaf_heading[leaf], k.leaf_left[leaf], k.leaf_up[leaf]};
}

void expect_orthonormal_right_handed(const Frame& f) {
  EXPECT_NEAR(f.h.norm(), 1.0, 1e-12);
  EXPECT_NEAR(f.l.norm(), 1.0, 1e-12);
  EXPECT_NEAR(f.h.dot(f.l), 0.0, 1e-12);
  expect_near(f.h.cross(f.l), f.u, 1e-12);
}

TEST(Turtle, GoldenPositions) {
  expect_near(draw("+(90)F(1)").segment_end[0], {-1, 0, 0});
  expect_near(draw("&(90)F(1)").segment_end[0], {0, 0, -1});
  const Skeleton k = draw("F(1)");
  expect_near(k.segment_start[0], {0, 0, 0});
  expect_near(k.segment_end[0], {0, 1, 0});
  expect_near(k.segment_up[0], {0, 0, 1});
}

// Each turn symbol is a right-handed rotation of the whole frame about one of its own axes.
struct TurnCase {
  char symbol;
  int axis;     // 0 H, 1 L, 2 U: the rotation axis, taken before the turn
  double sign;  // +1: right-handed by the angle, -1: by minus the angle
};

void PrintTo(const TurnCase& c, std::ostream* os) { *os << "'" << c.symbol << "'"; }

class TurnSymbol : public ::testing::TestWithParam<TurnCase> {};

TEST_P(TurnSymbol, MatchesAnalyticalRotationFromAnArbitraryFrame) {
  const TurnCase c = GetParam();
  const std::string setup = "+(31)&(47)/(13)";  // leaves the initial, axis-aligned frame
  for (const char* angle : {"(23)", "(-71)", ""}) {
    TurtleSettings settings;
    settings.angle_degrees = 17.0;
    const double degrees = *angle == '\0' ? 17.0 : std::strtod(angle + 1, nullptr);
    const Skeleton k = draw(setup + "L" + c.symbol + angle + "L", settings);
    ASSERT_EQ(k.leaf_count(), 2u);
    const Frame before = leaf_frame(k, 0);
    const Frame after = leaf_frame(k, 1);
    const Vector3d axis = c.axis == 0 ? before.h : c.axis == 1 ? before.l : before.u;
    const Eigen::AngleAxisd rotation(c.sign * degrees * kDeg, axis);
    expect_near(after.h, rotation * before.h);
    expect_near(after.l, rotation * before.l);
    expect_near(after.u, rotation * before.u);
    expect_orthonormal_right_handed(after);
  }
}

// + turns H toward L (about U), & pitches H toward -U (about L), \ rolls L toward -U (about H).
INSTANTIATE_TEST_SUITE_P(AllSix, TurnSymbol,
                         ::testing::Values(TurnCase{'+', 2, 1.0}, TurnCase{'-', 2, -1.0},
                                           TurnCase{'&', 1, 1.0}, TurnCase{'^', 1, -1.0},
                                           TurnCase{'\\', 0, -1.0}, TurnCase{'/', 0, 1.0}),
                         [](const auto& info) { return std::to_string(info.index); });

TEST(Turtle, TurnAroundIsHalfTurnAboutUpIgnoringItsParameter) {
  const Skeleton k = draw("&(30)+(20)L|L|(45)L");
  const Frame before = leaf_frame(k, 0);
  const Eigen::AngleAxisd half(std::numbers::pi, before.u);
  for (size_t leaf : {1u, 2u}) {
    const Frame f = leaf_frame(k, leaf);
    const Frame expected = leaf == 1 ? Frame{half * before.h, half * before.l, half * before.u} : before;
    expect_near(f.h, expected.h);
    expect_near(f.l, expected.l);
    expect_near(f.u, expected.u);
  }
}

TEST(Turtle, DefaultAngleAndStepFromSettings) {
  TurtleSettings settings;
  settings.angle_degrees = 30.0;
  settings.step = 2.5;
  const Skeleton k = draw("+F", settings);
  expect_near(k.segment_end[0], 2.5 * Vector3d(-std::sin(30 * kDeg), std::cos(30 * kDeg), 0));
}

TEST(Turtle, RollToHorizontalLeavesLeftHorizontalForRandomFrames) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-180.0, 180.0);
  for (int trial = 0; trial < 200; ++trial) {
    const std::string turns = "+(" + std::to_string(angle(rng)) + ")&(" + std::to_string(angle(rng)) +
                              ")/(" + std::to_string(angle(rng)) + ")";
    const Skeleton k = draw(turns + "L$L");
    const Frame before = leaf_frame(k, 0);
    const Frame after = leaf_frame(k, 1);
    EXPECT_NEAR(after.l.y(), 0.0, 1e-12) << turns;
    EXPECT_GE(after.u.y(), 0.0) << turns;  // L = V x H makes U point upward
    expect_near(after.h, before.h);        // a pure roll
    expect_orthonormal_right_handed(after);
  }
}

TEST(Turtle, RollToHorizontalKeepsFrameWhenHeadingIsVertical) {
  const Skeleton k = draw("/(40)L$L");  // H = (0,1,0) = V: every L is already horizontal
  expect_near(k.leaf_left[1], k.leaf_left[0], 0.0);
  expect_near(k.leaf_up[1], k.leaf_up[0], 0.0);
}

TEST(Turtle, TropismRotatesHeadingAboutHCrossTByElasticityTimesItsNorm) {
  TurtleSettings settings;
  settings.tropism = {0.5, 0, 0};
  settings.tropism_elasticity = 0.3;
  const Skeleton k = draw("F(1)F(1)F(1)", settings);
  // H = (0,1,0), T = (0.5,0,0): |H x T| = 0.5, so H turns by 0.15 rad toward +x.
  expect_near(k.segment_end[0], {0, 1, 0});
  const Vector3d h1(std::sin(0.15), std::cos(0.15), 0);
  expect_near(k.segment_end[1] - k.segment_start[1], h1);
  // Second bend: |H1 x T| = 0.5 cos(0.15).
  const double second = 0.15 + 0.3 * 0.5 * std::cos(0.15);
  expect_near(k.segment_end[2] - k.segment_start[2], {std::sin(second), std::cos(second), 0});
}

TEST(Turtle, TropismBendsTowardT) {
  TurtleSettings settings;
  settings.tropism = Vector3d(-0.61, 0.77, -0.19);
  settings.tropism_elasticity = 0.4;
  const Skeleton k = draw("&(70)/(20)FFFFFFFFL", settings);
  const Vector3d t = settings.tropism.normalized();
  double previous = -2.0;
  for (size_t s = 0; s < k.segment_count(); ++s) {
    const double alignment = (k.segment_end[s] - k.segment_start[s]).normalized().dot(t);
    EXPECT_GT(alignment, previous) << "segment " << s;
    previous = alignment;
  }
  expect_orthonormal_right_handed(leaf_frame(k, 0));
}

TEST(Turtle, ZeroElasticityOrHeadingAlongTDoesNotBend) {
  TurtleSettings settings;
  settings.tropism = {1, 0, 0};
  settings.tropism_elasticity = 0.0;
  expect_near(draw("FFF", settings).segment_end[2], {0, 3, 0}, 0.0);
  settings.tropism = {0, 2, 0};  // parallel to H: no torque
  settings.tropism_elasticity = 0.5;
  expect_near(draw("FFF", settings).segment_end[2], {0, 3, 0}, 0.0);
}

TEST(Turtle, BracketsRestorePositionFrameWidthAndMaterial) {
  const Skeleton k = draw("!(3)'F(1)[+(40)F(2)&(10)!(1)'(4)F(1)L]F(1)");
  ASSERT_EQ(k.segment_count(), 4u);
  expect_near(k.segment_start[3], {0, 1, 0});
  expect_near(k.segment_end[3], {0, 2, 0});
  EXPECT_EQ(k.segment_width[3], 3.0);
  EXPECT_EQ(k.segment_material[3], 1);
  EXPECT_EQ(k.segment_width[2], 1.0);
  EXPECT_EQ(k.segment_material[2], 4);
  expect_near(k.segment_up[3], {0, 0, 1});
}

TEST(Turtle, UnmatchedClosingBracketIsIgnored) {
  const Skeleton k = draw("F]F");
  expect_near(k.segment_end[1], {0, 2, 0});
}

struct Topology {
  std::vector<int32_t> parent;
  std::vector<uint8_t> continues;
  std::vector<int32_t> order;
  std::vector<uint32_t> id;
};

void expect_topology(const std::string& text, const Topology& expected) {
  const Skeleton k = draw(text);
  EXPECT_EQ(k.segment_parent, expected.parent) << text;
  EXPECT_EQ(k.segment_continues_parent, expected.continues) << text;
  EXPECT_EQ(k.segment_order, expected.order) << text;
  EXPECT_EQ(k.segment_id, expected.id) << text;
}

TEST(Turtle, ParentContinuationAndOrder) {
  // Modules: F [ + F ] F => ids 0 3 5.
  expect_topology("F[+F]F", {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}, {0, 3, 5}});
  // F [ + F [ - F ] ] F => ids 0 3 6 9.
  expect_topology("F[+F[-F]]F", {{-1, 0, 1, 0}, {0, 0, 0, 1}, {0, 1, 2, 0}, {0, 3, 6, 9}});
  // A move breaks continuity but not the axis; structural modules change nothing; G draws.
  expect_topology("FfFAXG", {{-1, 0, 1}, {0, 0, 1}, {0, 0, 0}, {0, 2, 5}});
  // A branch drawn before any segment has no parent.
  expect_topology("[F]F", {{-1, -1}, {0, 0}, {0, 0}, {1, 3}});
}

TEST(Turtle, LeavesAttachToTheCurrentSegment) {
  const Skeleton k = draw("LF(2)[+(90)L(0.5)]F[&~(2)]");
  ASSERT_EQ(k.leaf_count(), 3u);
  EXPECT_EQ(k.leaf_segment, (std::vector<int32_t>{-1, 0, 1}));
  EXPECT_EQ(k.leaf_scale, (std::vector<double>{1.0, 0.5, 2.0}));
  expect_near(k.leaf_position[1], {0, 2, 0});
  expect_near(k.leaf_heading[1], {-1, 0, 0});
  expect_near(k.leaf_left[1], {0, -1, 0});
  expect_near(k.leaf_up[1], {0, 0, 1});
  expect_near(k.leaf_position[2], {0, 3, 0});
  EXPECT_EQ(k.leaf_polygon_offsets, (std::vector<uint32_t>{0, 0, 0, 0}));
  EXPECT_TRUE(k.polygon_points.empty());
}

TEST(Turtle, PolygonBecomesALeafWithItsOutline) {
  // '.' records; inside { } G moves silently, F and f move and record, and nothing is drawn.
  const Skeleton k = draw("F(1)[{.G(1)+(90)F(1)+(90)f(1)}]L");
  ASSERT_EQ(k.segment_count(), 1u);
  ASSERT_EQ(k.leaf_count(), 2u);
  EXPECT_EQ(k.leaf_segment[0], 0);
  expect_near(k.leaf_position[0], {0, 1, 0});
  expect_near(k.leaf_heading[0], {0, 1, 0});
  EXPECT_EQ(k.leaf_scale[0], 1.0);
  EXPECT_EQ(k.leaf_polygon_offsets, (std::vector<uint32_t>{0, 3, 3}));
  ASSERT_EQ(k.polygon_points.size(), 3u);
  expect_near(k.polygon_points[0], {0, 1, 0});
  expect_near(k.polygon_points[1], {-1, 2, 0});
  expect_near(k.polygon_points[2], {-1, 1, 0});
}

TEST(Turtle, NestedPolygonsKeepTheirOwnOutlinesAndDegenerateOnesAreDropped) {
  const Skeleton k = draw("{.f(1)[{.+(90)G(1).-(90)G(1).}]-(90)f(1)}{.g.}");
  ASSERT_EQ(k.leaf_count(), 2u);
  EXPECT_EQ(k.leaf_polygon_offsets, (std::vector<uint32_t>{0, 3, 6}));
  // The inner one closes first.
  expect_near(k.polygon_points[0], {0, 1, 0});
  expect_near(k.polygon_points[1], {-1, 1, 0});
  expect_near(k.polygon_points[2], {-1, 2, 0});
  expect_near(k.leaf_position[0], {0, 1, 0});
  expect_near(k.polygon_points[3], {0, 0, 0});
  expect_near(k.polygon_points[4], {0, 1, 0});
  expect_near(k.polygon_points[5], {1, 1, 0});
  expect_near(k.leaf_position[1], {0, 0, 0});
}

TEST(Turtle, CutSkipsTheRestOfTheBranch) {
  const Skeleton k = draw("F[+F%F[F]L]F");
  ASSERT_EQ(k.segment_count(), 3u);
  EXPECT_EQ(k.leaf_count(), 0u);
  EXPECT_EQ(k.segment_parent, (std::vector<int32_t>{-1, 0, 0}));
  EXPECT_EQ(k.segment_continues_parent[2], 1);  // the ']' after the cut still restored the state
  EXPECT_EQ(draw("F%FF").segment_count(), 1u);  // a cut on the trunk ends the word
}

TEST(Turtle, WidthIsNaNWithoutBangThenSetOrScaled) {
  for (const double w : draw("FF[F]").segment_width) EXPECT_TRUE(std::isnan(w));
  TurtleSettings settings;
  settings.width_factor = 0.5;
  settings.initial_width = 4.0;
  EXPECT_EQ(draw("F!F!(0.3)F!F[!F]F", settings).segment_width,
            (std::vector<double>{4.0, 2.0, 0.3, 0.15, 0.075, 0.15}));
}

TEST(Turtle, MaterialIncrementsDecrementsAndSets) {
  EXPECT_EQ(draw("F'F'(5)F,F,(0)F,F'(2.6)F").segment_material,
            (std::vector<int32_t>{0, 1, 5, 4, 0, 0, 3}));
}

// cpfg's modules (docs/turtle.md "Symbols"): ';' and ',' step the colour index, '#' and
// '!' the width by the view file's increment.
TEST(Turtle, CpfgColourIndexSemicolonAndComma) {
  EXPECT_EQ(draw("F;F;(5)F,F,(0)F;F").segment_material, (std::vector<int32_t>{0, 1, 5, 4, 0, 1}));
}

TEST(Turtle, CpfgWidthStepsByTheViewIncrement) {
  TurtleSettings settings;
  settings.initial_width = 3.0;
  settings.width_increment = 0.5;
  EXPECT_EQ(draw("F#F#F!F!(1)F#(4)F!!!!!!!!!!F", settings).segment_width,
            (std::vector<double>{3.0, 3.5, 4.0, 3.5, 1.0, 4.0, 0.0}));
  settings.width_increment.reset();  // without a view file '#' adds 1 and '!' scales
  EXPECT_EQ(draw("F#F!F", settings).segment_width, (std::vector<double>{3.0, 4.0, 4.0 * settings.width_factor}));
}

// '~' with an id letter ("~l(s)") that no view-file surface has is a leaf of the default shape
// (view-file surfaces, spheres and circles: test_leaf_shapes.cpp).
TEST(Turtle, CpfgSurfacesWithoutAViewSurfaceAreDefaultLeaves) {
  const Skeleton k = draw("~l(4)F~l(2)F~(3)~");
  EXPECT_EQ(k.leaf_scale, (std::vector<double>{4.0, 2.0, 3.0, 1.0}));
  EXPECT_EQ(k.leaf_segment, (std::vector<int32_t>{-1, 0, 1, 1}));
  EXPECT_EQ(k.leaf_polygon_offsets, (std::vector<uint32_t>(5, 0)));
  EXPECT_EQ(k.leaf_triangle_offsets, (std::vector<uint32_t>(5, 0)));
  EXPECT_EQ(k.segment_count(), 2u);
}

// A view file's surface 'l': tests/data/cpfg/leaf.s, a flat 3 x 3 square with its contact point
// at a corner, drawn 1.5 long (3 x 2 quads: 12 points).
TurtleSettings with_test_surface() {
  TurtleSettings settings;
  const BezierSurface leaf = read_surface_file(std::string(TREEANIM_SOURCE_DIR) + "/tests/data/cpfg/leaf.s");
  settings.surfaces.push_back(surface_shape(leaf, 'l', 1.5, 3, 2));
  return settings;
}

// Leaf l's points (world) => their offsets from the leaf position in the leaf's (L, H, U).
std::vector<Vector3d> offsets_in_frame(const Skeleton& k, size_t l) {
  std::vector<Vector3d> out;
  for (uint32_t p = k.leaf_polygon_offsets[l]; p < k.leaf_polygon_offsets[l + 1]; ++p) {
    const Vector3d d = k.polygon_points[p] - k.leaf_position[l];
    out.emplace_back(d.dot(k.leaf_left[l]), d.dot(k.leaf_heading[l]), d.dot(k.leaf_up[l]));
  }
  return out;
}

// Twice the leaf's area as a vector: its front's direction.
Vector3d front_of(const Skeleton& k, size_t l) {
  const Vector3d* p = k.polygon_points.data() + k.leaf_polygon_offsets[l];
  Vector3d n = Vector3d::Zero();
  for (uint32_t t = k.leaf_triangle_offsets[l]; t < k.leaf_triangle_offsets[l + 1]; t += 3)
    n += (p[k.leaf_triangles[t + 1]] - p[k.leaf_triangles[t]]).cross(p[k.leaf_triangles[t + 2]] - p[k.leaf_triangles[t]]);
  return n;
}

// ~l(2): the contact point at the turtle, the surface twice its view size, the file's x along L,
// its heading along H, its front toward U; then the turtle stands at the end point.
TEST(Turtle, ViewSurfaceIsPlacedByTheTurtleFrame) {
  const Skeleton k = draw("F+(30)&(20)~l(2)F", with_test_surface());
  ASSERT_EQ(k.leaf_count(), 1u);
  EXPECT_EQ(k.leaf_segment[0], 0);
  EXPECT_EQ(k.leaf_polygon_offsets, (std::vector<uint32_t>{0, 12}));
  EXPECT_EQ(k.leaf_triangle_offsets, (std::vector<uint32_t>{0, 36}));
  const std::vector<Vector3d> d = offsets_in_frame(k, 0);
  expect_near(d[0], Vector3d::Zero());  // the contact point
  Vector3d lo = d[0], hi = d[0];
  for (const Vector3d& v : d) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  expect_near(lo, Vector3d::Zero(), 1e-12);
  expect_near(hi, Vector3d(3, 3, 0), 1e-12);  // 1.5 x 1.5 scaled by 2, toward +L and +H
  EXPECT_NEAR(front_of(k, 0).dot(k.leaf_up[0]), 2 * 9.0, 1e-9);
  expect_near(k.segment_start[1], k.leaf_position[0] + 3 * k.leaf_heading[0], 1e-12);  // the end point
}

TEST(Turtle, ViewSurfaceScalesPerAxisMirrorsAndSkipsZero) {
  const Skeleton k = draw("~l(2,1,1)~l(1,1,-1)~l(0)F", with_test_surface());
  ASSERT_EQ(k.leaf_count(), 2u);  // a zero scale draws nothing, as in cpfg
  Vector3d hi = Vector3d::Zero();
  for (const Vector3d& v : offsets_in_frame(k, 0)) hi = hi.cwiseMax(v);
  expect_near(hi, Vector3d(3, 1.5, 0), 1e-12);
  EXPECT_GT(front_of(k, 0).dot(k.leaf_up[0]), 0.0);
  EXPECT_LT(front_of(k, 1).dot(k.leaf_up[1]), 0.0);  // mirrored through the HL plane: its front faces -U
  // Each surface moved the turtle by its end point, 1.5 along H; ~l(0) did not move it.
  expect_near(k.segment_start[0], Vector3d(0, 3, 0), 1e-12);
}

// @O(d) a sphere, @c(d) @o(d) circles: small leaves of the sphere and disc shapes; without a
// parameter they round a joint and are left out.
TEST(Turtle, SpheresAndCirclesAreSmallLeavesUnlessTheyRoundAJoint) {
  const Skeleton k = draw("F@O(2)F@c(0.5)[@o(1)]@O@c@o", {});
  ASSERT_EQ(k.leaf_count(), 3u);
  EXPECT_EQ(k.leaf_segment, (std::vector<int32_t>{0, 1, 1}));
  EXPECT_EQ(k.leaf_polygon_offsets, (std::vector<uint32_t>{0, 6, 15, 24}));
  EXPECT_EQ(k.leaf_triangle_offsets, (std::vector<uint32_t>{0, 24, 48, 72}));
  const std::vector<Vector3d> sphere = offsets_in_frame(k, 0);
  for (const Vector3d& v : sphere) EXPECT_NEAR(v.norm(), 1.0, 1e-12);
  expect_near(sphere[0], Vector3d(0, -1, 0));  // the pole facing back along H: its attachment
  const std::vector<Vector3d> circle = offsets_in_frame(k, 1);
  expect_near(circle[0], Vector3d::Zero());  // the centre: its attachment
  for (size_t p = 1; p < circle.size(); ++p) {
    EXPECT_NEAR(circle[p].norm(), 0.25, 1e-12);
    EXPECT_NEAR(circle[p].z(), 0.0, 1e-12);  // in the HL plane
  }
  EXPECT_GT(front_of(k, 1).dot(k.leaf_up[1]), 0.0);
}

TEST(Turtle, CpfgRollMoveAndHeading) {
  const std::string turns = "+(30)&(40)/(50)";
  const Frame rolled = leaf_frame(draw(turns + "@vL"), 0);
  EXPECT_GT(std::abs(leaf_frame(draw(turns + "L"), 0).l.y()), 0.1);  // the roll has work to do
  EXPECT_NEAR(rolled.l.y(), 0.0, 1e-12);
  expect_near(rolled.h, leaf_frame(draw(turns + "$L"), 0).h);
  expect_near(rolled.l, leaf_frame(draw(turns + "$L"), 0).l);

  const Skeleton moved = draw("F@M(2,3,4)F");
  expect_near(moved.segment_start[1], Vector3d(2, 3, 4));
  expect_near(moved.segment_end[1], Vector3d(2, 4, 4));

  const Skeleton headed = draw("@R(2,0,0)F@R(0,0,1,0,1,0)F");
  expect_near(headed.segment_end[0], Vector3d(1, 0, 0));
  expect_near(headed.segment_end[1], Vector3d(1, 0, 1));
  expect_near(headed.segment_up[1], Vector3d(0, 1, 0));
  expect_orthonormal_right_handed(leaf_frame(draw("@R(1,1,0)L"), 0));
}

TEST(Turtle, CpfgGeneralisedCylinderMakesLowercaseFDraw) {
  const Skeleton k = draw("f@Gsf(2)f@Gef");
  ASSERT_EQ(k.segment_count(), 2u);
  expect_near(k.segment_start[0], Vector3d(0, 1, 0));
  expect_near(k.segment_end[1], Vector3d(0, 4, 0));
  EXPECT_EQ(k.segment_parent, (std::vector<int32_t>{-1, 0}));
}

TEST(Turtle, EmptyWordGivesAnEmptySkeleton) {
  const Skeleton k = draw("");
  EXPECT_EQ(k.segment_count(), 0u);
  EXPECT_EQ(k.leaf_polygon_offsets, (std::vector<uint32_t>{0}));
}

}  // namespace
}  // namespace treeanim
