// Surface materials: the per-triangle material of the built model, sRGB => linear base colours,
// and the per-leaf colour factors (deterministic in the seed, one factor per leaf).
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "tree/build_tree_model.h"
#include "tree/surface_materials.h"
#include "tree_test_util.h"

namespace treeanim {
namespace {

TEST(SurfaceMaterials, LeafTrianglesAreTheOnesOnLeafVertices) {
  const TreeModel m = build_tree_model(test::small_tree(), TreeOptions{});
  ASSERT_EQ(m.triangle_material.size(), m.triangle_count());
  size_t leaves = 0;
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    const bool on_leaf = m.vertex_leaf[m.triangles[3 * t]] >= 0;
    EXPECT_EQ(m.triangle_material[t], on_leaf ? kMaterialLeaf : kMaterialBark) << "triangle " << t;
    leaves += on_leaf;
  }
  EXPECT_GT(leaves, 0u);
  EXPECT_LT(leaves, m.triangle_count());
  const auto groups = material_triangles(m);
  EXPECT_EQ(groups[kMaterialLeaf].size(), leaves);
  EXPECT_EQ(groups[kMaterialBark].size() + leaves, m.triangle_count());
}

TEST(SurfaceMaterials, BaseColoursAreLinearAndLeavesDoubleSided) {
  TreeOptions o;
  o.bark_color = Eigen::Vector3d(0.5, 0.0, 1.0);
  const auto materials = surface_materials(o);
  EXPECT_STREQ(materials[kMaterialBark].name, "bark");
  EXPECT_STREQ(materials[kMaterialLeaf].name, "leaf");
  EXPECT_NEAR(materials[kMaterialBark].base_color[0], 0.21404, 1e-5);  // sRGB 0.5 is linear 0.214
  EXPECT_EQ(materials[kMaterialBark].base_color[1], 0.0f);
  EXPECT_EQ(materials[kMaterialBark].base_color[2], 1.0f);
  EXPECT_EQ(materials[kMaterialBark].base_color_srgb[0], 0.5f);
  EXPECT_NEAR(srgb_to_linear(0.04), 0.04 / 12.92, 1e-12);
  EXPECT_FALSE(materials[kMaterialBark].double_sided);
  EXPECT_TRUE(materials[kMaterialLeaf].double_sided);
  EXPECT_FLOAT_EQ(materials[kMaterialBark].roughness, 0.8f);
  EXPECT_FLOAT_EQ(materials[kMaterialLeaf].roughness, 0.6f);
}

TEST(SurfaceMaterials, LeafColourFactorsArePerLeafAndDeterministic) {
  const TreeModel m = build_tree_model(test::small_tree(), TreeOptions{});
  ASSERT_GT(m.leaf_count(), 1u);
  EXPECT_TRUE(leaf_color_factors(m, 0.0, 7).empty());
  const std::vector<float> a = leaf_color_factors(m, 0.5, 7);
  ASSERT_EQ(a.size(), 3 * m.vertex_count());
  EXPECT_EQ(a, leaf_color_factors(m, 0.5, 7));
  EXPECT_NE(a, leaf_color_factors(m, 0.5, 8));
  std::map<int32_t, std::vector<float>> of_leaf;  // the factor of each leaf's first vertex
  std::set<std::vector<float>> distinct;
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const std::vector<float> f(a.begin() + long(3 * v), a.begin() + long(3 * v + 3));
    for (float c : f) EXPECT_TRUE(c > 0.5f && c <= 1.0f) << "vertex " << v;
    if (m.vertex_leaf[v] < 0) {
      EXPECT_EQ(f, std::vector<float>(3, 1.0f)) << "bark vertex " << v;
      continue;
    }
    const auto [first, inserted] = of_leaf.emplace(m.vertex_leaf[v], f);
    EXPECT_EQ(f, first->second) << "vertex " << v << " of leaf " << m.vertex_leaf[v];
    distinct.insert(f);
  }
  EXPECT_EQ(distinct.size(), m.leaf_count());
}

}  // namespace
}  // namespace treeanim
