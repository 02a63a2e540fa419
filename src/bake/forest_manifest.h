#pragma once
// The forest manifest (docs/outputs.md "Forest manifest"): a part per finished tree in
// OUT/forest.parts/<id>.json, written by whichever process baked it, and OUT/forest.json, the
// parts of every tree in forest order, written once all are complete (farm gather).
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bake/bake_config.h"
#include "bake/bake_tree.h"
#include "scene/scene.h"

namespace treeanim {

// out_dir ("" = the working folder), tree id => the tree's part file.
std::filesystem::path tree_part_path(const std::filesystem::path& out_dir, const std::string& id);
// out_dir => the forest manifest.
std::filesystem::path forest_manifest_path(const std::filesystem::path& out_dir);

// Writes tree `index`'s part in config.out_dir (atomically) after its outputs are all in place;
// it carries the tree's bake_key(), and a part of another key belongs to an older bake.
void write_tree_part(const BakeConfig& config, const Scene& forest_scene, size_t index, const Scene& tree_scene,
                     const TreeBakeResult& result);

// The tree's part when its bake is complete: the part is there, of this key, and every file it
// lists exists; else nullopt, with the reason in `why` and `*foreign` set when the part is the
// tree's own of another key (another scene or treeanim version).
std::optional<Json> complete_tree_part(const std::filesystem::path& out_dir, const std::string& id,
                                       const std::string& key, std::string& why, bool* foreign = nullptr);

// What gather_forest writes, added to `targets` (formats/outputs.h): the manifest, and beside
// it the stage or the page when the scene has a usd or an html output. `written` false: a
// shard's bake, which gathers nothing but must not write where the gather will.
void add_forest_targets(const Scene& scene, const std::filesystem::path& out_dir, OutputTargets& targets,
                        bool written = true);

// The forest's own files in out_dir (the manifest, and its stage and page), each removed where it
// is a regular file: they say the trees beside them are one complete forest, which a bake that
// rewrites a tree, or a gather that finds one missing, makes untrue. => whether one was there.
bool remove_forest_files(const std::filesystem::path& out_dir);

struct GatherReport {
  std::vector<size_t> missing;       // trees whose bake is not complete, ascending
  std::vector<std::string> reasons;  // (missing) why
  bool removed_stale = false;        // trees missing: an earlier manifest, stage or page was removed
  // Every tree's part is its own of another scene or treeanim version: the folder holds a
  // forest, not this scene's, and its files were left as they are.
  bool other_scene = false;
};

// Every tree complete (its part of this generator's key) => writes OUT/forest.json, removes
// the folder of the trees' checkpoints (`checkpoints`, "" for none) when their bakes left it
// empty, and returns no missing trees; else removes the forest's files (remove_forest_files)
// and returns them, unless every part is of another scene (GatherReport::other_scene): then
// the gather's scene is not the folder's, and its files stay. Throws OutputError when the manifest cannot be written.
GatherReport gather_forest(const Scene& scene, const std::filesystem::path& out_dir, const std::string& generator,
                           const std::filesystem::path& checkpoints);

}  // namespace treeanim
