#pragma once
// The forest page (docs/outputs.md "Preview page"): forest.html beside the forest manifest, the
// trees' preview pages composed into one, each tree placed where the forest puts it, so one
// page plays the whole forest.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace treeanim {

// One tree of the page.
struct ForestPageTree {
  std::string id;                                        // the forest's tree id
  std::filesystem::path page;                            // the tree's preview page, as written (its own frame)
  Eigen::Vector3d translation = Eigen::Vector3d::Zero(); // m, world position of the tree's base
  double rotation_degrees = 0;                           // about +Y, counter-clockwise seen from above
};

// trees (at least one), name, size limit => the page's text: every tree's mesh and kept frames,
// the wind plotted at the first tree, the displacements over all trees. Frames the limit has no
// room for are thinned alike in every tree (every k-th and the last kept); when the trees do not
// fit even with two frames each, the first ones that do are shown and the others left out; the
// page says what it reduced. A tree's page leaves room for a forest page of that tree alone, so a
// forest page is never refused for its size. A tree's scale is grown into its mesh, so nothing
// scales. Reads each page twice (its sizes, then the trees shown), holding one at a time besides
// the page it composes. Throws OutputError naming a page that cannot be read or plots other frames.
std::string forest_page(const std::vector<ForestPageTree>& trees, const std::string& name, size_t max_page_bytes);

// Writes forest_page() to `path` (named after its stem) atomically. Throws OutputError naming the path.
void write_forest_page(const std::filesystem::path& path, const std::vector<ForestPageTree>& trees,
                       size_t max_page_bytes);

}  // namespace treeanim
