// USDA text and the forest stage: numbers that read back as the same float, USD's row-vector
// matrices, prim names made of any id, and forest.usda's prims.
#include <gtest/gtest.h>

#include <cstdlib>

#include "formats/usd_forest.h"
#include "formats/usd_text.h"

namespace treeanim {
namespace {

TEST(UsdText, FloatsReadBackBitForBit) {
  for (float value : {0.1f, 1.0f / 3.0f, -2.5e-7f, 211864.125f, 3.4028235e38f}) {
    std::string text;
    append_usd_number(text, value);
    EXPECT_EQ(std::strtof(text.c_str(), nullptr), value) << text;
  }
  std::string text;
  append_usd_number(text, 0.1f);
  EXPECT_EQ(text, "0.1");  // the shortest text, not the double nearest the float
}

TEST(UsdText, TuplesAndMatrices) {
  const float values[] = {1, 2, 3, 4.5f, -5, 6};
  std::string text;
  append_usd_tuples(text, values, 2, 3);
  EXPECT_EQ(text, "[(1, 2, 3), (4.5, -5, 6)]");
  text.clear();
  // A quarter turn about +Y takes +X to -Z: USD's first row is the image of +X.
  Eigen::Matrix3d quarter_turn;
  quarter_turn << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  append_usd_matrix(text, quarter_turn, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(text, "((0, 0, -1, 0), (0, 1, 0, 0), (1, 0, 0, 0), (1, 2, 3, 1))");
}

TEST(UsdText, PrimNamesFromIds) {
  EXPECT_EQ(usd_prim_name("oak-1"), "oak_1");
  EXPECT_EQ(usd_prim_name("2b"), "_2b");
  EXPECT_EQ(usd_prim_name("c.3"), "c_3");
  EXPECT_EQ(usd_quoted("a \"b\" \\"), "\"a \\\"b\\\" \\\\\"");
}

// An '@' would end a one-@ asset path: such a path takes USD's @@@ delimiters.
TEST(UsdText, AssetPathsWithAnAt) {
  EXPECT_EQ(usd_asset_path("./t/a.usda"), "@./t/a.usda@");
  EXPECT_EQ(usd_asset_path("./t@x/a.usda"), "@@@./t@x/a.usda@@@");
  EXPECT_EQ(usd_asset_path("a@@@b"), "@@@a\\@@@b@@@");
}

TEST(UsdForest, APrimPerTreeReferencingItsLayer) {
  const std::string text = forest_usda(
      {{"a-b", "trees/a-b.usda", {1, 0, -2}, 30}, {"a.b", "/abs/a.b.usda", {0, 0, 0}, -90}}, {24, 2, 11});
  EXPECT_NE(text.find("startTimeCode = 2\n"), std::string::npos);
  EXPECT_NE(text.find("endTimeCode = 11\n"), std::string::npos);
  EXPECT_NE(text.find("def \"a_b\" (\n"), std::string::npos);
  EXPECT_NE(text.find("prepend references = @./trees/a-b.usda@"), std::string::npos);
  EXPECT_NE(text.find("double3 xformOp:translate = (1, 0, -2)"), std::string::npos);
  EXPECT_NE(text.find("double xformOp:rotateY = 30\n"), std::string::npos);
  // The clash takes the tree's place in the list; an absolute layer stays as it is.
  EXPECT_NE(text.find("def \"a_b_1\" (\n"), std::string::npos);
  EXPECT_NE(text.find("string treeanim_id = \"a.b\""), std::string::npos);
  EXPECT_NE(text.find("prepend references = @/abs/a.b.usda@"), std::string::npos);
}

}  // namespace
}  // namespace treeanim
