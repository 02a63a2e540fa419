// vertex_normals: area-weighted, unit length, the front face of a one-sided sheet, and a finite
// fallback where no triangle of non-zero area says anything.
#include <gtest/gtest.h>

#include <cmath>

#include "formats/vertex_normals.h"

namespace treeanim {
namespace {

// A model of `positions` (3 x V) and `triangles`; the rest pose is `positions`.
TreeModel mesh(const Eigen::Matrix3Xd& positions, std::vector<uint32_t> triangles) {
  TreeModel m;
  m.rest_positions = positions;
  m.triangles = std::move(triangles);
  return m;
}

std::vector<float> as_float(const Eigen::Matrix3Xd& positions) {
  return std::vector<float>(positions.data(), positions.data() + positions.size());
}

TEST(VertexNormals, FlatSheetFacesItsCounterClockwiseSide) {
  Eigen::Matrix3Xd p(3, 4);
  p << 0, 1, 1, 0,  //
      0, 0, 0, 0,   //
      0, 0, -1, -1;  // a unit square in the XZ plane, counter-clockwise seen from +Y
  const TreeModel m = mesh(p, {0, 1, 2, 0, 2, 3});
  std::vector<float> normals;
  vertex_normals(m, as_float(p).data(), {}, normals);
  for (size_t v = 0; v < 4; ++v) {
    EXPECT_EQ(normals[3 * v], 0.0f);
    EXPECT_EQ(normals[3 * v + 1], 1.0f);
    EXPECT_EQ(normals[3 * v + 2], 0.0f);
  }
}

TEST(VertexNormals, WeightedByTriangleArea) {
  // Vertex 0 is shared by a triangle of area 2 facing +Z and one of area 0.5 facing +X.
  Eigen::Matrix3Xd p(3, 5);
  p << 0, 2, 0, 0, 0,  //
      0, 0, 2, 1, 0,   //
      0, 0, 0, 0, 1;
  const TreeModel m = mesh(p, {0, 1, 2, 0, 3, 4});
  std::vector<float> normals;
  vertex_normals(m, as_float(p).data(), {}, normals);
  const double length = std::sqrt(2.0 * 2.0 + 0.5 * 0.5);
  EXPECT_FLOAT_EQ(normals[0], float(0.5 / length));
  EXPECT_FLOAT_EQ(normals[1], 0.0f);
  EXPECT_FLOAT_EQ(normals[2], float(2.0 / length));
}

TEST(VertexNormals, CollapsedTrianglesTakeTheFallback) {
  Eigen::Matrix3Xd p(3, 4);
  p << 0, 1, 0, 5,  //
      0, 0, 1, 5,   //
      0, 0, 0, 5;   // vertex 3 is on no triangle
  const TreeModel m = mesh(p, {0, 1, 2});
  const std::vector<float> rest = rest_normals(m);
  EXPECT_EQ(std::vector<float>(rest.begin() + 9, rest.end()), (std::vector<float>{0, 1, 0}));  // +Y
  Eigen::Matrix3Xd collapsed = p;
  collapsed.col(1) = collapsed.col(0);  // the triangle has no area
  std::vector<float> normals;
  vertex_normals(m, as_float(collapsed).data(), rest, normals);
  EXPECT_EQ(normals, rest);
  for (size_t v = 0; v < 4; ++v) {
    const double length = std::hypot(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]);
    EXPECT_NEAR(length, 1.0, 1e-7);
  }
}

}  // namespace
}  // namespace treeanim
