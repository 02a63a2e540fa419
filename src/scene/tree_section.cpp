#include "scene/tree_section.h"

namespace treeanim {

// A branch radius, m: the thickest trunk known (the Arbol del Tule, about 11 m across) has a radius
// under 6 m.
constexpr Range kRadius{0, 10, true, false};

// /tree/leaf object => leaf options (defaults written back into the scene).
static LeafOptions read_leaf_options(SceneObject section, LeafOptions o) {
  o.size = section.number("size", o.size, {0, 25, true, false});
  o.aspect = section.number("aspect", o.aspect, {0, 10, true, false});
  o.petiole = section.number("petiole", o.petiole, Range::between(0, 10));
  o.areal_density = section.number("areal_density", o.areal_density, {0, 20, true, false});
  if (auto mesh = section.optional_path("mesh")) o.mesh = mesh;
  return o;
}

// An sRGB colour: three numbers in [0, 1] (validated here: vector3 takes any finite numbers).
static Eigen::Vector3d read_color(SceneObject& section, const std::string& key, const Eigen::Vector3d& fallback) {
  const Eigen::Vector3d color = section.vector3(key, fallback);
  if (color.minCoeff() < 0 || color.maxCoeff() > 1)
    section.fail_expected(key, "an sRGB colour: an array of 3 numbers in [0, 1]");
  return color;
}

// /tree/cluster object => cluster options.
static ClusterOptions read_cluster_options(SceneObject section, ClusterOptions o) {
  o.segments_per_cluster =
      int(section.integer("segments_per_cluster", o.segments_per_cluster, 1, 1'000'000));
  o.target_vertices = int(section.integer("target_vertices", o.target_vertices, 0, 100'000'000));
  return o;
}

TreeOptions read_tree_options(SceneObject section, TreeOptions o) {
  o.scale = section.number("scale", o.scale, {0, 100, true, false});
  o.width_scale = section.number("width_scale", o.width_scale, Range::positive());
  o.ring_sides = int(section.integer("ring_sides", o.ring_sides, 3, 256));
  o.trunk_radius = section.number("trunk_radius", o.trunk_radius, kRadius);
  o.min_radius = section.number("min_radius", o.min_radius, kRadius);
  o.wood_density = section.number("wood_density", o.wood_density, Range::between(50, 1500));
  o.pipe_exponent = section.number("pipe_exponent", o.pipe_exponent, Range::between(1.0, 4.0));
  o.tip_taper = section.number("tip_taper", o.tip_taper, Range::between(0.0, 1.0));
  o.drag_share = section.number("drag_share", o.drag_share, {0, 1, true, false});
  o.bark_color = read_color(section, "bark_color", o.bark_color);
  o.leaf_color = read_color(section, "leaf_color", o.leaf_color);
  o.leaf_color_variation = section.number("leaf_color_variation", o.leaf_color_variation, Range::between(0.0, 1.0));
  o.leaf = read_leaf_options(section.object("leaf"), o.leaf);
  o.cluster = read_cluster_options(section.object("cluster"), o.cluster);
  return o;
}

}  // namespace treeanim
