// read_tree_options: defaults, nested objects, paths, error messages.
#include <gtest/gtest.h>

#include "common/errors.h"
#include "scene/tree_section.h"

namespace treeanim {
namespace {

TEST(TreeOptions, DefaultsAreFilledIntoTheScene) {
  Json document = Json::parse(R"({"tree": {}})");
  SceneReader reader(document, "/scenes");
  const TreeOptions o = read_tree_options(reader.root().object("tree"));
  reader.check_unknown_keys();
  EXPECT_EQ(o.ring_sides, 8);
  EXPECT_EQ(o.wood_density, 700);
  EXPECT_EQ(o.pipe_exponent, 2);
  EXPECT_FALSE(o.leaf.mesh);
  EXPECT_EQ(document["tree"]["ring_sides"], 8);
  EXPECT_EQ(document["tree"]["leaf"]["size"], 0.08);
  EXPECT_EQ(document["tree"]["cluster"]["segments_per_cluster"], 1);
}

TEST(TreeOptions, ValuesAndRelativeMeshPath) {
  Json document = Json::parse(
      R"({"tree": {"scale": 0.01, "ring_sides": 6, "leaf": {"mesh": "leaves/oak.glb", "size": 0.1},
                   "cluster": {"segments_per_cluster": 3, "target_vertices": 40}}})");
  SceneReader reader(document, "/scenes");
  const TreeOptions o = read_tree_options(reader.root().object("tree"));
  reader.check_unknown_keys();
  EXPECT_EQ(o.scale, 0.01);
  EXPECT_EQ(o.ring_sides, 6);
  EXPECT_EQ(o.leaf.mesh->string(), "/scenes/leaves/oak.glb");
  EXPECT_EQ(o.leaf.size, 0.1);
  EXPECT_EQ(o.cluster.segments_per_cluster, 3);
  EXPECT_EQ(o.cluster.target_vertices, 40);
}

// read_tree_options on `text` => the InputError message.
std::string tree_error_of(const std::string& text) {
  Json document = Json::parse(text);
  try {
    SceneReader reader(document, "/scenes", "s.json");
    read_tree_options(reader.root().object("tree"));
    reader.check_unknown_keys();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(TreeOptions, BadValuesNameThePointer) {
  EXPECT_EQ(tree_error_of(R"({"tree": {"ring_sides": 2}})"),
            "s.json: /tree/ring_sides: expected an integer in [3, 256], got 2");
  EXPECT_EQ(tree_error_of(R"({"tree": {"leaf": {"size": 0}}})"),
            "s.json: /tree/leaf/size: expected a number in (0, 25], got 0");
  EXPECT_EQ(tree_error_of(R"({"tree": {"cluster": {"segment_per_cluster": 2}}})"),
            "s.json: /tree/cluster/segment_per_cluster: unknown key (did you mean "
            "/tree/cluster/segments_per_cluster?)");
}

TEST(TreeOptions, ColoursAreSrgbTriplesInTheUnitRange) {
  Json document = Json::parse(R"({"tree": {"bark_color": [0.5, 0.4, 0.3], "leaf_color_variation": 0}})");
  SceneReader reader(document, "/scenes");
  const TreeOptions o = read_tree_options(reader.root().object("tree"));
  EXPECT_EQ(o.bark_color, Eigen::Vector3d(0.5, 0.4, 0.3));
  EXPECT_EQ(o.leaf_color, TreeOptions{}.leaf_color);
  EXPECT_EQ(o.leaf_color_variation, 0);
  EXPECT_EQ(document["tree"]["leaf_color"], Json::parse("[0.3, 0.47, 0.16]"));
  EXPECT_EQ(tree_error_of(R"({"tree": {"leaf_color": [0.2, 1.5, 0.1]}})"),
            "s.json: /tree/leaf_color: expected an sRGB colour: an array of 3 numbers in [0, 1], got [0.2,1.5,0.1]");
  EXPECT_EQ(tree_error_of(R"({"tree": {"bark_color": [0.2, 0.1]}})"),
            "s.json: /tree/bark_color: expected an array of 3 finite numbers, got [0.2,0.1]");
  EXPECT_EQ(tree_error_of(R"({"tree": {"leaf_color_variation": -0.1}})"),
            "s.json: /tree/leaf_color_variation: expected a number in [0, 1], got -0.1");
}

}  // namespace
}  // namespace treeanim
