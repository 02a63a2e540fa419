// cpfg surface files and the leaf shapes made of them (docs/turtle.md "Surfaces, spheres and
// circles"): the file's format and its errors, the tessellation, the frame, the sphere and disc.
// The surface files are written for these tests (tests/data/cpfg/leaf.s and variants of it).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <string>

#include "temp_folder_test.h"
#include "common/errors.h"
#include "common/read_text_file.h"
#include "lsystem/leaf_shapes.h"
#include "lsystem/surface_file.h"

namespace treeanim {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;

// The surface file the tests share (tests/data/cpfg/leaf.s) => its text.
std::string test_surface_text() {
  std::string text, reason;
  if (!read_text_file(fs::path(TREEANIM_SOURCE_DIR) / "tests/data/cpfg/leaf.s", text, reason)) ADD_FAILURE() << reason;
  return text;
}

// A fresh folder per test for the files it writes.
class SurfaceFile : public TempFolderTest {
 protected:
  SurfaceFile() : TempFolderTest("treeanim_surface") {}

  BezierSurface read(const std::string& text) const {
    std::ofstream(dir_ / "leaf.s") << text;
    return read_surface_file(dir_ / "leaf.s");
  }
  // The test surface with `from` replaced by `to` (once) => the error, without the folder.
  std::string error_of(const std::string& from, const std::string& to) const {
    std::string text = test_surface_text();
    const size_t at = text.find(from);
    if (at == std::string::npos) return "test error: no '" + from + "'";
    text.replace(at, from.size(), to);
    try {
      read(text);
    } catch (const InputError& e) {
      const std::string message = e.what(), prefix = dir_.string() + "/";
      return message.rfind(prefix, 0) == 0 ? message.substr(prefix.size()) : message;
    }
    return "no error";
  }

};

TEST_F(SurfaceFile, ReadsTheHeaderAndThePatch) {
  const BezierSurface s = read(test_surface_text());
  EXPECT_EQ(s.precision, (std::array<int, 2>{3, 2}));
  EXPECT_EQ(s.contact, Vector3d(-1.5, 0, 0));
  EXPECT_EQ(s.end, Vector3d(-1.5, 3, 0));
  EXPECT_EQ(s.heading, Vector3d(0, 1, 0));
  EXPECT_EQ(s.up, Vector3d(0, 0, 1));
  EXPECT_EQ(s.size, 3.0);
  ASSERT_EQ(s.patches.size(), 1u);
  EXPECT_EQ(s.patches[0][0], Vector3d(-1.5, 0, 0));
  EXPECT_EQ(s.patches[0][6], Vector3d(0.5, 1, 0));  // row 1, column 2
  EXPECT_EQ(s.patches[0][15], Vector3d(1.5, 3, 0));
}

// stedit's VERSION line, no PRECISION, neighbour lines with more words, a second patch, a
// heading and up that are neither unit nor perpendicular (made so, as cpfg does).
TEST_F(SurfaceFile, AcceptsWhatStEditAndBezierEditWrite) {
  std::string text = "VERSION stedit\n" + test_surface_text();
  text.replace(text.find("PRECISION S: 3 T: 2\n"), 20, "");
  text.replace(text.find("HEADING  X: 0.00 Y: 1.00"), 24, "HEADING  X: 0.00 Y: 2.00");
  text.replace(text.find("UP  X: 0.00 Y: 0.00"), 19, "UP  X: 0.00 Y: 1.00");
  text.replace(text.find("AL: ~ A: ~ AR: ~"), 16, "AL: ~ none A: ~ none AR: ~ none");
  const std::string patch = text.substr(text.find("blade"));
  const BezierSurface s = read(text + patch);
  EXPECT_FALSE(s.precision);
  EXPECT_EQ(s.patches.size(), 2u);
  EXPECT_NEAR((s.heading - Vector3d(0, 1, 0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((s.up - Vector3d(0, 0, 1)).norm(), 0.0, 1e-15);
}

TEST_F(SurfaceFile, ErrorsNameTheLineColumnAndWhatWasExpected) {
  EXPECT_EQ(error_of("-1.50 1.50", "-1.50 wide"),
            "leaf.s:1:7: expected a number: the bounding box 'xmin xmax ymin ymax zmin zmax', got 'wide'");
  EXPECT_EQ(error_of("PRECISION S: 3 T: 2", "PRECISION S: 3 T: 2.5"), "leaf.s:2:19: expected a whole number of quads, got '2.5'");
  EXPECT_EQ(error_of("CONTACT POINT", "CONTACT PONT"),
            "leaf.s:3:9: expected 'CONTACT POINT  X: x Y: y Z: z', got 'PONT'");
  EXPECT_EQ(error_of("END POINT  X: -1.50 Y: 3.00 Z: 0.00", "END POINT  X: -1.50 Y: 3.00"),
            "leaf.s:5:1: expected 'END POINT  X: x Y: y Z: z', got 'HEADING'");
  EXPECT_EQ(error_of("HEADING  X: 0.00 Y: 1.00", "HEADING  X: 0.00 Y: 0.00"), "leaf.s:5:1: expected a non-zero HEADING, got 'HEADING'");
  EXPECT_EQ(error_of("UP  X: 0.00 Y: 0.00 Z: 1.00", "UP  X: 0.00 Y: -2 Z: 0"),
            "leaf.s:6:1: expected an UP vector that is not parallel to the HEADING, got 'UP'");
  EXPECT_EQ(error_of("SIZE: 3.00", "SIZE: 0"), "leaf.s:7:7: expected a SIZE > 0, got '0'");
  EXPECT_EQ(error_of("SIZE: 3.00", "SIZE 3"), "leaf.s:7:1: expected 'SIZE: s', got 'SIZE'");
  EXPECT_EQ(error_of("TOP COLOR", "TOP_COLOR"), "leaf.s:9:1: expected the line 'TOP ...' of patch 'blade', got 'TOP_COLOR:'");
  EXPECT_EQ(error_of("BL: ~", "BR: ~"), "leaf.s:12:1: expected the line 'BL: ...' of patch 'blade', got 'BR:'");
  EXPECT_EQ(error_of("0.5 2 0  1.5 2 0", "0.5 2 0  1.5 2 x"),
            "leaf.s:15:36: expected a number: control point 12 of 16 (x y z) of patch 'blade', got 'x'");
  EXPECT_EQ(error_of("1.5 3 0\n", "1.5 3\n"),
            "leaf.s:16:35: expected a number: control point 16 of 16 (x y z) of patch 'blade', got the end of the file");
  EXPECT_EQ(error_of("-0.5 1 0", "-0.5 1 nan"),
            "leaf.s:14:18: expected a number: control point 6 of 16 (x y z) of patch 'blade', got 'nan'");
}

TEST_F(SurfaceFile, NoPatchOrNoFileAreErrors) {
  std::string text = test_surface_text();
  text.erase(text.find("blade"));
  try {
    read(text);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("leaf.s:7:11: expected a patch"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_surface_file(dir_ / "none.s"), InputError);
}

// The test surface: a flat 3 x 3 patch with its contact point at a corner, SIZE 3.
BezierSurface test_surface() {
  BezierSurface s;
  s.contact = {-1.5, 0, 0};
  s.end = {-1.5, 3, 0};
  s.size = 3;
  std::array<Vector3d, 16> patch;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) patch[static_cast<size_t>(4 * i + j)] = Vector3d(j - 1.5, i, 0);
  s.patches = {patch};
  return s;
}

// Twice the area of every triangle, summed as vectors: the shape's mean normal times 2 area.
Vector3d summed_normal(const LeafShape& shape) {
  Vector3d n = Vector3d::Zero();
  for (size_t t = 0; t < shape.triangles.size(); t += 3) {
    const Vector3d& a = shape.points[shape.triangles[t]];
    n += (shape.points[shape.triangles[t + 1]] - a).cross(shape.points[shape.triangles[t + 2]] - a);
  }
  return n;
}

TEST(SurfaceShape, GridScaleFrameAndFront) {
  const LeafShape shape = surface_shape(test_surface(), 'l', 1.5, 3, 2);
  EXPECT_EQ(shape.id, 'l');
  ASSERT_EQ(shape.points.size(), 12u);       // (3 + 1) x (2 + 1)
  EXPECT_EQ(shape.triangles.size(), 12u * 3);  // 2 per quad
  // The contact point is the origin; SIZE 3 is drawn 1.5 long: the factor is 0.5.
  EXPECT_NEAR(shape.points[0].norm(), 0.0, 1e-15);
  Vector3d lo = shape.points[0], hi = lo;
  for (const Vector3d& p : shape.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // The file's +x is drawn along the turtle's L (cpfg: left = HEADING x UP), which is -x here.
  EXPECT_NEAR((lo - Vector3d(-1.5, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((hi - Vector3d(0, 1.5, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((shape.end - Vector3d(0, 1.5, 0)).norm(), 0.0, 1e-15);
  const Vector3d n = summed_normal(shape);
  EXPECT_NEAR(n.z(), 2 * 1.5 * 1.5, 1e-12);  // all of it faces +z (the turtle's U)
  EXPECT_NEAR(n.head<2>().norm(), 0.0, 1e-12);
}

// The test surface turned (x, y, z) => (-x, -z, -y), with HEADING and UP turned alike: the
// same shape.
TEST(SurfaceShape, HeadingAndUpOfTheFileBecomeHAndU) {
  BezierSurface s = test_surface();
  for (Vector3d& p : s.patches[0]) p = Vector3d(-p.x(), -p.z(), -p.y());
  s.contact = {1.5, 0, 0};
  s.end = {1.5, 0, -3};
  s.heading = {0, 0, -1};
  s.up = {0, -1, 0};
  const LeafShape turned = surface_shape(s, 'l', 3, 1, 1);
  const LeafShape straight = surface_shape(test_surface(), 'l', 3, 1, 1);
  ASSERT_EQ(turned.points.size(), straight.points.size());
  for (size_t k = 0; k < turned.points.size(); ++k) EXPECT_NEAR((turned.points[k] - straight.points[k]).norm(), 0.0, 1e-12);
  EXPECT_NEAR((turned.end - straight.end).norm(), 0.0, 1e-12);
}

// Two patches sharing an edge (the second the first moved by 3 along y, reversed in t): the
// shared points are one point, and a patch with a collapsed edge loses its empty triangles.
TEST(SurfaceShape, PatchesAreWeldedAtTheirSharedEdges) {
  BezierSurface s = test_surface();
  std::array<Vector3d, 16> above;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) above[static_cast<size_t>(4 * i + j)] = Vector3d(1.5 - j, 3 + i, 0);
  s.patches.push_back(above);
  const LeafShape shape = surface_shape(s, 'l', 3, 2, 2);
  EXPECT_EQ(shape.points.size(), 9u + 9u - 3u);
  EXPECT_EQ(shape.triangles.size(), 2u * 8 * 3);
  for (uint32_t v : shape.triangles) EXPECT_LT(v, shape.points.size());

  BezierSurface fan = test_surface();
  for (int j = 0; j < 4; ++j) fan.patches[0][static_cast<size_t>(j)] = Vector3d(-1.5, 0, 0);  // row 0: one point
  const LeafShape triangle = surface_shape(fan, 'l', 3, 2, 2);
  EXPECT_EQ(triangle.points.size(), 9u - 2u);
  EXPECT_EQ(triangle.triangles.size(), (8u - 2u) * 3);

  // 6,000 patches stacked on one another weld into one patch's points (pair by pair the weld
  // compared 726,000 points at one place, for minutes), their triangles kept, each doubled.
  BezierSurface stack = test_surface();
  stack.patches.assign(6000, stack.patches[0]);
  const LeafShape stacked = surface_shape(stack, 'l', 3, 10, 10);
  EXPECT_EQ(stacked.points.size(), 121u);
  EXPECT_EQ(stacked.triangles.size(), 6000u * 200 * 3);
}

TEST(SurfaceShape, SphereAndDiscAreClosedOutwardAndFlatUpward) {
  const LeafShape& sphere = sphere_shape();
  ASSERT_EQ(sphere.points.size(), 6u);
  ASSERT_EQ(sphere.triangles.size(), 8u * 3);
  EXPECT_EQ(sphere.points[0], Vector3d(0, -0.5, 0));  // the pole facing back along H first
  for (size_t t = 0; t < sphere.triangles.size(); t += 3) {
    const Vector3d& a = sphere.points[sphere.triangles[t]];
    const Vector3d& b = sphere.points[sphere.triangles[t + 1]];
    const Vector3d& c = sphere.points[sphere.triangles[t + 2]];
    EXPECT_GT((b - a).cross(c - a).dot(a + b + c), 0.0) << "triangle " << t / 3 << " faces inward";
  }
  EXPECT_NEAR(summed_normal(sphere).norm(), 0.0, 1e-15);  // closed
  const LeafShape& disc = disc_shape();
  ASSERT_EQ(disc.points.size(), 9u);
  EXPECT_EQ(disc.points[0], Vector3d::Zero());
  for (size_t k = 1; k < 9; ++k) EXPECT_NEAR(disc.points[k].norm(), 0.5, 1e-15);
  const Vector3d n = summed_normal(disc);
  EXPECT_GT(n.z(), 0.0);
  EXPECT_NEAR(n.head<2>().norm(), 0.0, 1e-15);
}

}  // namespace
}  // namespace treeanim
