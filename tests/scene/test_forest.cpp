// /forest (docs/scene.md "forest"): scatter determinism and spacing, listed trees, the one-tree
// scene of each tree, and the refusals with their JSON pointers.
#include <gtest/gtest.h>

#include "common/errors.h"
#include "scene/forest_layout.h"
#include "scene/scene.h"

namespace treeanim {
namespace {

Scene load_forest(const std::string& forest, const std::string& outputs = "[]") {
  return load_scene_text(R"({"lsystem": {"axiom": "F", "iterations": 0}, "forest": )" + forest +
                             R"(, "outputs": )" + outputs + "}",
                         "f.json", "/scenes", {});
}

std::string forest_error_of(const std::string& forest, const std::string& outputs = "[]") {
  try {
    load_forest(forest, outputs);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

double nearest_pair(const std::vector<Eigen::Vector2d>& points) {
  double nearest = 1e300;
  for (size_t i = 0; i < points.size(); ++i)
    for (size_t j = 0; j < i; ++j) nearest = std::min(nearest, (points[i] - points[j]).norm());
  return nearest;
}

TEST(ForestLayout, ScatterIsDeterministicAndKeepsTheSpacing) {
  const ScatterArea area{{-20, -10}, {20, 10}};
  const std::vector<Eigen::Vector2d> fixed{{0, 0}};
  const auto a = scatter_points(42, 100, area, 2.0, 1000, fixed);
  const auto b = scatter_points(42, 100, area, 2.0, 1000, fixed);
  const auto c = scatter_points(43, 100, area, 2.0, 1000, fixed);
  ASSERT_EQ(a.size(), 100u);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  auto all = a;
  all.push_back(fixed.front());
  EXPECT_GE(nearest_pair(all), 2.0);
  for (const auto& p : a) {
    EXPECT_TRUE(p.x() >= -20 && p.x() <= 20 && p.y() >= -10 && p.y() <= 10) << p.transpose();
  }
}

TEST(ForestLayout, AFullAreaStopsAtWhatFits) {
  // A 4 m square holds at most 9 points 2 m apart (plus boundary luck): never 100.
  const auto placed = scatter_points(1, 100, {{0, 0}, {4, 4}}, 2.0, 200, {});
  EXPECT_LT(placed.size(), 100u);
  EXPECT_GE(placed.size(), 3u);
  EXPECT_GE(nearest_pair(placed), 2.0);
}

// Spacings far below the grid's 1 mm cells, and coordinates far beyond, are kept exactly:
// 1e-300 m places the trees as no spacing does (a cell index once overflowed there), and two
// trees 0.1 mm apart, 0.05 mm apart or 1e9 m from the origin are told apart.
TEST(ForestLayout, SpacingsBelowTheCellsAndFarCoordinates) {
  const ScatterArea area{{-1e4, -1e4}, {1e4, 1e4}};
  EXPECT_EQ(scatter_points(5, 2000, area, 1e-300, 10, {}), scatter_points(5, 2000, area, 0, 10, {}));
  EXPECT_FALSE(closer_than({{0, 0}, {1e-4, 0}}, 1e-4));
  EXPECT_TRUE(closer_than({{0, 0}, {0.5e-4, 0}}, 1e-4));
  EXPECT_TRUE(closer_than({{1e9, -1e9}, {1e9 + 0.5, -1e9}}, 1.0));
  EXPECT_FALSE(closer_than({{1e300, 0}, {-1e300, 0}}, 1e-300));
}

TEST(ForestLayout, CloserThanNamesThePair) {
  const auto pair = closer_than({{0, 0}, {10, 0}, {10.5, 0}}, 1.0);
  ASSERT_TRUE(pair);
  EXPECT_EQ(pair->first, 1u);
  EXPECT_EQ(pair->second, 2u);
  EXPECT_FALSE(closer_than({{0, 0}, {10, 0}, {10.5, 0}}, 0.4));
}

TEST(Forest, ListedAndScatteredTrees) {
  const Scene scene = load_forest(R"({"spacing": 1, "variants": [{"name": "a", "weight": 1}, {"name": "b", "weight": 3,
      "lsystem": {"axiom": "FF", "iterations": 0}}], "trees": [{"id": "hero", "variant": "b", "position": [1, 0, 2],
      "rotation": 30, "scale": 2, "seed": 5}, {}], "scatter": {"count": 40, "min": [-10, -10], "max": [10, 10],
      "seed": 3}})",
                                  R"([{"format": "hdf5", "path": "t/{tree}.h5"}])");
  const Forest& forest = *scene.forest;
  ASSERT_EQ(forest.trees.size(), 42u);
  EXPECT_EQ(forest.trees[0].id, "hero");
  EXPECT_EQ(forest.trees[0].variant, 1u);
  EXPECT_EQ(forest.trees[0].seed, 5u);
  EXPECT_EQ(forest.trees[1].id, "0001");  // padded index
  EXPECT_EQ(forest.trees[1].variant, 0u);  // the first variant
  EXPECT_EQ(forest.trees[41].id, "0041");
  size_t b = 0;
  for (size_t t = 2; t < 42; ++t) {
    b += forest.trees[t].variant;
    EXPECT_GE(forest.trees[t].rotation, 0);
    EXPECT_LT(forest.trees[t].rotation, 360);
    EXPECT_EQ(forest.trees[t].position.y(), 0);
  }
  EXPECT_GT(b, 20u);  // weight 3 of 4
  EXPECT_LT(b, 40u);
  // The same scene places the same trees.
  const Scene again = load_forest(scene.resolved["forest"].dump(), R"([{"format": "hdf5", "path": "t/{tree}.h5"}])");
  for (size_t t = 0; t < 42; ++t) {
    EXPECT_EQ(again.forest->trees[t].position, forest.trees[t].position);
    EXPECT_EQ(again.forest->trees[t].seed, forest.trees[t].seed);
  }
}

// Only the weights' ratios count, at any size: equal weights of 1e308 (whose sum overflows)
// draw as 1 and 1, a subnormal weight beside 0 takes every tree, and a weight 0 none.
TEST(Forest, WeightsDrawByTheirRatiosAlone) {
  auto variants_of = [](const std::string& a, const std::string& b) {
    const Scene scene =
        load_forest(R"({"spacing": 1, "variants": [{"name": "a", "weight": )" + a + R"(}, {"name": "b", "weight": )" +
                    b + R"(}], "scatter": {"count": 30, "min": [-10, -10], "max": [10, 10], "seed": 3}})");
    std::vector<size_t> variants;
    for (const ForestTree& tree : scene.forest->trees) variants.push_back(tree.variant);
    return variants;
  };
  const std::vector<size_t> even = variants_of("1", "1");
  EXPECT_EQ(variants_of("1e308", "1e308"), even);
  EXPECT_EQ(variants_of("5e-324", "5e-324"), even);
  EXPECT_EQ(variants_of("3", "3"), even);
  EXPECT_EQ(variants_of("5e-324", "0"), std::vector<size_t>(30, 0));
  EXPECT_EQ(variants_of("0", "1e-310"), std::vector<size_t>(30, 1));
  EXPECT_EQ(variants_of("1.7e308", "0"), std::vector<size_t>(30, 0));
}

// A scatter of no trees (a count set to 0 to leave it out for a while) holds the keys of one of
// more, checked as they are there, and places nothing.
TEST(Forest, ScatterOfNoTreesKeepsItsKeys) {
  const Scene scene = load_forest(R"({"trees": [{}], "scatter": {"count": 0, "min": [-10, -10], "max": [10, 10],
      "seed": 3, "attempts": 50, "rotation": [0, 90], "scale": [0.5, 2]}})");
  EXPECT_EQ(scene.forest->trees.size(), 1u);
  EXPECT_EQ(
      forest_error_of(R"({"trees": [{}], "scatter": {"count": 0, "min": [0, 0], "max": [1, 1], "scale": [2, 1]}})"),
      "f.json: /forest/scatter/scale: expected [lo, hi] with lo <= hi, got [2,1]");
  EXPECT_EQ(forest_error_of(R"({"trees": [{}], "scatter": {"count": 0, "min": [0, 0]}})"),
            "f.json: /forest/scatter/max: expected the area's corners min and max, each [x, z] in m");
}

TEST(Forest, TreeSceneIsTheTreesOwnScene) {
  const Scene scene =
      load_forest(R"({"variants": [{"name": "a"}, {"name": "b", "lsystem": {"axiom": "FF", "iterations": 0},
      "tree": {"ring_sides": 5}}], "trees": [{"id": "x"}, {"id": "y", "variant": "b", "scale": 2, "seed": 9}]})",
                  R"([{"format": "hdf5", "path": "t/{tree}/{tree}.h5"}])");
  const Scene y = tree_scene(scene, 1);
  EXPECT_EQ(y.outputs[0].path, "t/y/y.h5");
  EXPECT_EQ(y.lsystem.axiom, "FF");
  EXPECT_EQ(y.lsystem.seed, 9u);
  EXPECT_EQ(y.tree.ring_sides, 5);
  EXPECT_EQ(y.tree.scale, 2.0);
  EXPECT_EQ(y.tree.trunk_radius, 0.2);
  EXPECT_FALSE(y.forest);
  ASSERT_EQ(y.resolved["forest"]["trees"].size(), 1u);
  EXPECT_EQ(y.resolved["forest"]["trees"][0]["id"], "y");
  EXPECT_EQ(y.resolved["forest"]["variants"][0]["name"], "b");
  // Its resolved scene is a scene again: the forest of that one tree.
  const Scene reloaded = load_scene_text(y.resolved.dump(), "y.json", "/scenes", {});
  const Scene y2 = tree_scene(reloaded, 0);
  EXPECT_EQ(y2.resolved.dump(), y.resolved.dump());
  EXPECT_EQ(tree_scene(scene, 0).lsystem.axiom, "F");
}

TEST(Forest, Refusals) {
  EXPECT_EQ(forest_error_of(R"({"trees": []})"),
            "f.json: /forest/trees: a forest with no trees: list trees in /forest/trees or give "
            "/forest/scatter/count >= 1");
  EXPECT_EQ(forest_error_of(R"({"spacing": 2, "trees": [{"position": [5, 9, 0]}, {"position": [1, 0, 0.5]},
      {"position": [0.5, 0, 1]}]})"),
            "f.json: /forest/trees/2/position: 0.707107 m from /forest/trees/1 on the ground, closer than "
            "/forest/spacing = 2 m: move one of them or lower the spacing");
  EXPECT_NE(
      forest_error_of(R"({"spacing": 2, "scatter": {"count": 50, "min": [0, 0], "max": [4, 4], "attempts": 100}})")
          .find("f.json: /forest/scatter/count: placed "),
      std::string::npos);
  EXPECT_NE(
      forest_error_of(R"({"spacing": 2, "scatter": {"count": 50, "min": [0, 0], "max": [4, 4], "attempts": 100}})")
          .find(" of 50 trees in the area with /forest/spacing 2 m (100 darts each)"),
      std::string::npos);
  EXPECT_EQ(forest_error_of(R"({"trees": [{"variant": "oak"}]})"),
            "f.json: /forest/trees/0/variant: expected one of the variants' names (\"default\"), got \"oak\"");
  EXPECT_EQ(forest_error_of(R"({"trees": [{"id": "a"}, {"id": "a"}]})"),
            "f.json: /forest/trees: two trees have the id \"a\" (/forest/trees/0 and /forest/trees/1): ids name the "
            "trees' files, give each its own");
  EXPECT_EQ(forest_error_of(R"({"trees": [{"id": "../x"}]})"),
            "f.json: /forest/trees/0/id: expected an id of 1 to 64 letters, digits, '_', '-' or '.' (not first), got "
            "\"../x\"");
  EXPECT_EQ(forest_error_of(R"({"trees": [{}, {}]})", R"([{"format": "hdf5", "path": "bake.h5"}])"),
            "f.json: /outputs/0/path: the forest has 2 trees and this path no {tree}: every tree would write the same "
            "file; put the tree's id in it, e.g. \"trees/{tree}.h5\"");
  EXPECT_EQ(forest_error_of(R"({"trees": [{}], "sprcing": 1})"),
            "f.json: /forest/sprcing: unknown key (did you mean /forest/spacing?)");
}

// null is an unset value: a forest of null is the one tree, and a null section within a forest
// or a variant takes what a missing one would (docs/scene.md).
TEST(Forest, NullSectionsTakeTheirDefaults) {
  const Scene one = load_scene_text(R"({"lsystem": {"axiom": "F", "iterations": 0}, "forest": null,
      "wind": {"volume": null}, "outputs": [{"format": "usd", "path": "a.usda", "max_joints": null}]})",
                                    "f.json", "/scenes", {});
  EXPECT_FALSE(one.forest);
  EXPECT_FALSE(one.wind.volume);
  const Scene scene = load_scene_text(R"({"lsystem": {"axiom": "F", "iterations": 0}, "tree": {"scale": 2},
      "forest": {"variants": [{"name": "a", "tree": null, "lsystem": null, "hsm": null}], "trees": [{}],
      "scatter": null}})",
                                      "f.json", "/scenes", {});
  ASSERT_TRUE(scene.forest);
  EXPECT_EQ(scene.forest->trees.size(), 1u);
  const Scene tree = tree_scene(scene, 0);
  EXPECT_EQ(tree.tree.scale, 2.0);  // the top level's tree, as for a variant without one
  EXPECT_EQ(tree.lsystem.axiom, "F");
  EXPECT_EQ(load_forest(R"({"variants": null, "trees": [{}]})").forest->trees.size(), 1u);
}

TEST(Forest, OneTreeSceneRefusesThePlaceholder) {
  try {
    load_scene_text(R"({"lsystem": {"axiom": "F"}, "outputs": [{"format": "hdf5", "path": "{tree}.h5"}]})", "s.json",
                    "/scenes", {});
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "s.json: /outputs/0/path: {tree} stands for the id of a tree of a /forest, and "
                                     "this scene has no /forest: remove it from the path");
  }
}

}  // namespace
}  // namespace treeanim
