// validate_tree_model: catches corrupted index arrays with a precise message.
#include <gtest/gtest.h>

#include <functional>

#include "common/errors.h"
#include "tree/build_tree_model.h"
#include "tree_test_util.h"

namespace treeanim {
namespace {

// Corrupts a valid model with `mutate` => validate_tree_model's message ("" if it passes).
std::string error_after(const std::function<void(TreeModel&)>& mutate) {
  TreeModel m = build_tree_model(test::small_tree(), TreeOptions{});
  mutate(m);
  try {
    validate_tree_model(m);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ValidateTreeModel, AcceptsABuiltModel) { EXPECT_EQ(error_after([](TreeModel&) {}), ""); }

TEST(ValidateTreeModel, CatchesCorruptedIndices) {
  EXPECT_EQ(error_after([](TreeModel& m) { m.cluster_members[5] = uint32_t(m.vertex_count()); }),
            "tree model: cluster_members[5] = 70 out of range [0, 70)");
  EXPECT_EQ(error_after([](TreeModel& m) { m.triangles[7] = 1000; }),
            "tree model: triangles[7] = 1000 out of range [0, 70)");
  EXPECT_EQ(error_after([](TreeModel& m) { m.cluster_parent[3] = 3; }),
            "tree model: cluster_parent[3] = 3 is not an earlier cluster");
  EXPECT_EQ(error_after([](TreeModel& m) { m.leaf_cluster[1] = 0; }),
            "tree model: leaf_cluster[1] is not the leaf's cluster");
  EXPECT_EQ(error_after([](TreeModel& m) { std::swap(m.vertex_memberships[8], m.vertex_memberships[9]); }),
            "tree model: vertex_memberships of vertex 8 not in ascending cluster order");
  EXPECT_EQ(error_after([](TreeModel& m) { m.member_cluster[5] = 1; }),
            "tree model: member_cluster[5] = 1 is not cluster 0, which holds the slot");
  EXPECT_EQ(error_after([](TreeModel& m) { m.vertex_cluster_offsets.pop_back(); }),
            "tree model: vertex_cluster_offsets has 70 entries, expected 71");
  EXPECT_EQ(error_after([](TreeModel& m) { m.triangle_material[3] = 2; }),
            "tree model: triangle_material[3] = 2 out of range [0, 2)");
  EXPECT_EQ(error_after([](TreeModel& m) { m.triangle_material.pop_back(); }),
            "tree model: triangle_material has 101 entries, expected 102");
}

TEST(ValidateTreeModel, AnEmptySkeletonIsAnInputError) {
  try {
    build_tree_model(Skeleton{}, TreeOptions{});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "the grammar draws nothing: no segment (F, G) and no leaf (L, ~, { . })");
  }
}

}  // namespace
}  // namespace treeanim
