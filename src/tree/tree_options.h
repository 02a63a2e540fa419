#pragma once
// Scene section /tree (docs/scene.md), read by scene/ (src/scene/tree_section.h).
#include <Eigen/Core>
#include <filesystem>
#include <optional>

namespace treeanim {

// /tree/leaf: the shape instanced on every L / ~ module without a '{ . }' outline.
struct LeafOptions {
  double size = 0.08;           // m, leaf blade length (a custom mesh's largest extent)
  double aspect = 0.5;          // blade width / length of the default quad
  double petiole = 0.01;        // m, gap between the attachment point and the blade base
  double areal_density = 0.15;  // kg/m^2, leaf mass per blade area
  std::optional<std::filesystem::path> mesh;  // custom leaf mesh (any format assimp reads)
};

// /tree/cluster: how consecutive segments of one axis are merged into shape-matching clusters.
struct ClusterOptions {
  int segments_per_cluster = 1;  // segments of one axis per branch cluster (at most)
  int target_vertices = 0;       // > 0: also close a cluster before it exceeds this many members
};

struct TreeOptions {
  double scale = 1.0;          // metres per scene unit
  double width_scale = 1.0;    // extra factor on '!' widths (ABOP's widths are line widths)
  int ring_sides = 8;          // vertices per branch ring
  double trunk_radius = 0.1;   // m, trunk base radius when the grammar sets no widths
  double min_radius = 0.002;   // m, no branch thinner
  double wood_density = 700;   // kg/m^3
  double pipe_exponent = 2.0;  // k of the pipe model r_parent^k = sum r_child^k
  double tip_taper = 0.5;      // top / base radius of a segment that ends an axis
  // The share of its segments' and leaf cards' own drag that the crown feels: 1 takes each as
  // if alone in the air; a grown crown, whose parts shelter each other and streamline, feels
  // 0.1 to 0.3 of it (the species, docs/species.md "Drag")
  double drag_share = 1.0;
  // Base colours of the two surface materials, sRGB in [0, 1] as a colour picker gives them
  // (tree/surface_materials.h converts them for glTF, whose factors are linear).
  Eigen::Vector3d bark_color = Eigen::Vector3d(0.36, 0.27, 0.19);  // grey-brown bark
  Eigen::Vector3d leaf_color = Eigen::Vector3d(0.30, 0.47, 0.16);  // mid green foliage
  double leaf_color_variation = 0.3;  // 0 = every leaf leaf_color; 1 = the widest per-leaf spread
  LeafOptions leaf;
  ClusterOptions cluster;
};

// options, factor => the options of the same tree `factor` times as large: every length (scale,
// radii, leaf size and petiole) multiplied, so masses follow the volume and the sway the size.
TreeOptions scaled_tree_options(TreeOptions options, double factor);

}  // namespace treeanim
