#include "bake/forest_manifest.h"

#include <unistd.h>

#include <algorithm>

#include "bake/scene_hash.h"
#include "common/json_text.h"
#include "common/message_text.h"
#include "common/read_text_file.h"
#include "files/output_lock.h"
#include "files/text_output.h"
#include "formats/html_forest.h"
#include "formats/usd_forest.h"
#include "output/output_formats.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

Json vector_json(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

// A file an output wrote => how the manifest names it: relative to the manifest's folder when
// it lies there, else as it is.
std::string manifest_name(const fs::path& file, const fs::path& out_dir) {
  if (out_dir.empty() || file.is_absolute() != out_dir.is_absolute()) return file.string();
  const fs::path relative = file.lexically_relative(out_dir.lexically_normal());
  return relative.empty() || *relative.begin() == ".." ? file.string() : relative.string();
}

// The column-major 4x4 matrix (glTF's order) that takes a point of the tree's files to the world.
Json placement_matrix(const TreePlacement& placement) {
  Json matrix = Json::array();
  for (int column = 0; column < 4; ++column)
    for (int row = 0; row < 4; ++row)
      matrix.push_back(row == 3      ? (column == 3 ? 1.0 : 0.0)
                       : column == 3 ? placement.translation[row]
                                     : placement.rotation(row, column));
  return matrix;
}

// The parts' trees => each one's first file of `format`, or none unless every tree has one.
std::vector<std::string> first_files(const Json& trees, const std::string& format) {
  std::vector<std::string> files;
  for (const Json& tree : trees) {
    const Json& outputs = tree.at("outputs");
    const auto found =
        std::find_if(outputs.begin(), outputs.end(), [&](const Json& o) { return o.at("format") == format; });
    if (found == outputs.end()) return {};
    files.push_back(found->at("files").at(0).get<std::string>());
  }
  return files;
}

Eigen::Vector3d position_of(const Json& tree) {
  const Json& position = tree.at("position");
  return {position[0].get<double>(), position[1].get<double>(), position[2].get<double>()};
}

// The parts' trees with their first USD layer each, or none unless every tree has one.
std::vector<ForestStageTree> usd_stage_trees(const Json& trees) {
  std::vector<ForestStageTree> stage;
  const std::vector<std::string> layers = first_files(trees, "usd");
  for (size_t t = 0; t < layers.size(); ++t)
    stage.push_back({trees[t].at("id").get<std::string>(), layers[t], position_of(trees[t]),
                     trees[t].at("rotation").get<double>()});
  return stage;
}

// The parts' trees with their first preview page each, or none unless every tree has one.
std::vector<ForestPageTree> page_trees(const Json& trees, const fs::path& out_dir) {
  std::vector<ForestPageTree> pages;
  const std::vector<std::string> files = first_files(trees, "html");
  for (size_t t = 0; t < files.size(); ++t) {
    const fs::path page(files[t]);
    pages.push_back({trees[t].at("id").get<std::string>(), page.is_absolute() ? page : out_dir / page,
                     position_of(trees[t]), trees[t].at("rotation").get<double>()});
  }
  return pages;
}

fs::path forest_stage_path(const fs::path& out_dir) { return out_dir / "forest.usda"; }

fs::path forest_page_path(const fs::path& out_dir) { return out_dir / "forest.html"; }

// The scene's first output of `format`, or null.
const OutputOptions* first_output(const Scene& scene, const std::string& format) {
  const auto found = std::find_if(scene.outputs.begin(), scene.outputs.end(),
                                  [&](const OutputOptions& o) { return o.format->name == format; });
  return found == scene.outputs.end() ? nullptr : &*found;
}

// A part without its digest => the digest of its text: a part edited by hand (another tree's
// id, another file) no longer matches the one written with it.
std::string part_digest(const Json& part) { return scene_hash(part.dump(), "forest part"); }

}  // namespace

fs::path tree_part_path(const fs::path& out_dir, const std::string& id) {
  return out_dir / "forest.parts" / (id + ".json");
}

fs::path forest_manifest_path(const fs::path& out_dir) { return out_dir / "forest.json"; }

void write_tree_part(const BakeConfig& config, const Scene& forest_scene, size_t index, const Scene& tree_scene,
                     const TreeBakeResult& result) {
  const fs::path& out_dir = config.out_dir;
  const ForestTree& tree = forest_scene.forest->trees[index];
  Json outputs = Json::array();
  for (size_t k = 0; k < tree_scene.outputs.size(); ++k) {
    Json files = Json::array();
    for (const fs::path& file : result.files[k]) files.push_back(manifest_name(file, out_dir));
    outputs.push_back({{"format", tree_scene.outputs[k].format->name}, {"files", std::move(files)}});
  }
  Json part = {
      {"id", tree.id},
      {"variant", forest_scene.forest->variants[tree.variant].name},
      {"seed", tree.seed},
      {"position", vector_json(tree.position)},
      {"rotation", tree.rotation},
      {"scale", tree.scale},
      {"matrix", placement_matrix(make_tree_placement(tree.position, tree.rotation))},
      {"bounds", {{"min", vector_json(result.bounds.min())}, {"max", vector_json(result.bounds.max())}}},
      {"frame_start", result.written.first},
      {"frame_count", result.written.count()},
      {"vertices", result.vertices},
      {"outputs", std::move(outputs)},
      {"bake", bake_key(tree_scene, config.generator)}};
  part["digest"] = part_digest(part);
  write_text_output(tree_part_path(out_dir, tree.id), part.dump(2) + "\n");
}

std::optional<Json> complete_tree_part(const fs::path& out_dir, const std::string& id, const std::string& key,
                                       std::string& why, bool* foreign) {
  const fs::path path = tree_part_path(out_dir, id);
  std::string text, reason;
  if (!read_text_file(path, text, reason, kMaxTextFileBytes, TextFileRole::kOwnOutput)) {
    why = "not baked (no " + path.string() + ")";
    return std::nullopt;
  }
  Json part;
  try {
    part = parse_json_text(text, path.string());
    if (part.at("bake").get<std::string>() != key) {
      const std::string of = part.at("id").get<std::string>();
      why = path.string() + (of != id ? " is the part of tree " + printable_text(of) + ", copied here"
                                      : " is of another scene or treeanim version");
      if (foreign) *foreign = of == id;
      return std::nullopt;
    }
    const std::string digest = part.at("digest").get<std::string>();
    part.erase("digest");
    if (digest != part_digest(part) || part.at("id").get<std::string>() != id) {
      why = path.string() + " was edited after its tree was baked (it no longer matches its digest or names "
                            "another tree)";
      return std::nullopt;
    }
    for (const Json& output : part.at("outputs"))
      for (const Json& name : output.at("files")) {
        const fs::path file(name.get<std::string>());
        std::error_code error;
        if (!fs::is_regular_file(file.is_absolute() ? file : out_dir / file, error)) {
          why = "its file " + file.string() + " is missing";
          return std::nullopt;
        }
      }
  } catch (const std::exception& error) {
    why = path.string() + " cannot be read: " + error.what();
    return std::nullopt;
  }
  return part;
}

void add_forest_targets(const Scene& scene, const fs::path& out_dir, OutputTargets& targets, bool written) {
  targets.add_file(forest_manifest_path(out_dir), "the forest's manifest", written);
  targets.add_lock(lock_path(forest_manifest_path(out_dir)), "the forest's manifest");
  if (first_output(scene, "usd")) targets.add_file(forest_stage_path(out_dir), "the forest's USD stage", written);
  if (first_output(scene, "html")) targets.add_file(forest_page_path(out_dir), "the forest's page", written);
}

bool remove_forest_files(const fs::path& out_dir) {
  bool removed = false;
  for (const fs::path& file : {forest_manifest_path(out_dir), forest_stage_path(out_dir), forest_page_path(out_dir)}) {
    std::error_code error;
    if (fs::is_regular_file(fs::symlink_status(file, error))) removed = fs::remove(file, error) || removed;
  }
  return removed;
}

GatherReport gather_forest(const Scene& scene, const fs::path& out_dir, const std::string& generator,
                           const fs::path& checkpoints) {
  GatherReport report;
  Json trees = Json::array();
  size_t foreign_parts = 0;
  for (size_t t = 0; t < scene.forest->trees.size(); ++t) {
    std::string why;
    bool foreign = false;
    const Scene one = tree_scene(scene, t);
    auto part = complete_tree_part(out_dir, scene.forest->trees[t].id, bake_key(one, generator), why, &foreign);
    foreign_parts += foreign ? 1 : 0;
    if (!part) {
      report.missing.push_back(t);
      report.reasons.push_back(why);
    } else if (report.missing.empty()) {
      trees.push_back(std::move(*part));
    }
  }
  // Every part another scene's: a gather given another scene or --set than the forest was baked
  // with, whose manifest still describes the folder.
  report.other_scene = foreign_parts == scene.forest->trees.size();
  if (!report.missing.empty()) {
    if (!report.other_scene) report.removed_stale = remove_forest_files(out_dir);
    return report;
  }
  // Before the manifest, which says the forest is complete.
  if (const auto stage = usd_stage_trees(trees); !stage.empty()) {
    const long long start = trees[0].at("frame_start").get<long long>();
    write_forest_usda(forest_stage_path(out_dir), stage,
                      {scene.time.fps, start, start + std::max(1LL, trees[0].at("frame_count").get<long long>()) - 1});
  }
  if (const auto pages = page_trees(trees, out_dir); !pages.empty())
    write_forest_page(forest_page_path(out_dir), pages, first_output(scene, "html")->max_page_bytes);
  const Json manifest = {{"format", "treeanim-forest"},
                         {"format_version", 1},
                         {"generator", generator},
                         {"units", "m"},
                         {"up_axis", "Y"},
                         {"fps", scene.time.fps},
                         {"trees", std::move(trees)}};
  write_text_output(forest_manifest_path(out_dir), manifest.dump(2) + "\n");
  // Each finished tree removed its spent checkpoints; rmdir leaves a folder with files, or a link.
  if (!checkpoints.empty()) ::rmdir(checkpoints.c_str());
  return report;
}

}  // namespace treeanim
