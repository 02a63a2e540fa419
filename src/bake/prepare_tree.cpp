#include "bake/prepare_tree.h"

#include <chrono>
#include <limits>

#include "common/errors.h"
#include "common/seconds_since.h"
#include "lsystem/lsystem.h"
#include "sim/particle_model.h"
#include "tree/build_tree_model.h"

namespace treeanim {

namespace {

Json to_json(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

}  // namespace

PreparedTree prepare_tree(const Scene& scene, MeshSurface surface,
                          const std::function<void(int step, int steps, size_t modules)>& grown_step) {
  PreparedTree tree;
  auto start = std::chrono::steady_clock::now();
  tree.skeleton = grow_skeleton(scene.lsystem, &tree.growth, grown_step);
  tree.grow_seconds = seconds_since(start);
  start = std::chrono::steady_clock::now();
  try {
    tree.model = build_tree_model(tree.skeleton, scene.tree, surface);
  } catch (const TreeModelError& e) {
    // What the model refuses comes from what the grammar drew, at the scene's lengths and widths: name them.
    const std::string forest = scene.forest_tree.empty() ? "" : ", and of " + scene.forest_tree;
    throw InputError(grammar_name(scene.lsystem) + ": the tree it draws cannot be built (its lengths and widths "
                     "times lsystem.step, tree.scale and tree.width_scale" + forest + "): " + e.what());
  }
  tree.model_seconds = seconds_since(start);
  return tree;
}

Json tree_summary(const Scene& scene, const PreparedTree& tree) {
  const Skeleton& skeleton = tree.skeleton;
  const TreeModel& model = tree.model;

  double total_length = 0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (size_t s = 0; s < skeleton.segment_count(); ++s) {
    total_length += (skeleton.segment_end[s] - skeleton.segment_start[s]).norm();
    for (const Eigen::Vector3d& p : {skeleton.segment_start[s], skeleton.segment_end[s]}) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  if (skeleton.segment_count() == 0) lo = hi = Eigen::Vector3d::Zero();

  double mass = 0;
  for (double m : model.vertex_mass) mass += m;
  const long long bytes_per_frame = static_cast<long long>(model.vertex_count()) * 3 * 4;

  Json summary;
  summary["derivation"] = {{"modules", tree.growth.modules}, {"iterations", tree.growth.iterations}};
  summary["skeleton"] = {{"segments", skeleton.segment_count()},
                         {"leaves", skeleton.leaf_count()},
                         {"total_length", total_length},
                         {"bbox_min", to_json(lo)},
                         {"bbox_max", to_json(hi)}};
  summary["mesh"] = {{"vertices", model.vertex_count()}, {"triangles", model.triangle_count()}};
  summary["model"] = {{"clusters", model.cluster_count()},
                      {"memberships", model.membership_count()},
                      {"leaf_clusters", model.leaf_count()},
                      {"anchored_vertices",
                       std::count(model.vertex_anchored.begin(), model.vertex_anchored.end(), 1)},
                      {"mass_kg", mass}};
  // hsm.particles "samples": what the solver will move instead of the mesh's vertices.
  if (scene.hsm.particles == ParticleMode::kSamples) {
    const TreeModel samples = sample_tree_model(model);
    summary["model"]["samples"] = samples.vertex_count();
    summary["model"]["sample_memberships"] = samples.membership_count();
  }
  summary["estimate"] = {{"frames", scene.time.frames},
                         {"substeps_total", scene.time.frames * scene.time.substeps},
                         {"bytes_per_frame", bytes_per_frame},
                         {"bytes_positions_total", bytes_per_frame * scene.time.frames}};
  summary["timing"] = {{"grow_seconds", tree.grow_seconds}, {"model_seconds", tree.model_seconds}};
  return summary;
}

}  // namespace treeanim
