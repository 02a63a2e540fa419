#pragma once
// What a bake is asked to do (docs/checkpoint.md, docs/farm.md): built once by the command line
// from its arguments, so that nothing below cli/ reads a command-line string.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

#include "scene/scene.h"

namespace treeanim {

// "treeanim <version>": the writer that outputs, checkpoints and the forest manifest record.
std::string treeanim_generator();

// One-tree scene, generator => the key of its bake: the hash of its resolved scene, the bytes
// of the files it names or its grammars read (Scene::input_paths), the sizes and times of its
// volume frames (Scene::volume_frames) and the generator, that its checkpoints, frame
// journal and manifest part carry. The plan derives it from
// the scene rather than take it from the config, so that the two cannot disagree.
std::string bake_key(const Scene& scene, const std::string& generator);

struct FrameRange {
  long long first = 0;  // inclusive
  long long last = 0;   // inclusive
  long long count() const { return last - first + 1; }
};

// One farm task of a forest (docs/farm.md "Shards").
struct Shard {
  size_t index = 0;  // 0-based task
  size_t count = 1;  // tasks
};

struct CheckpointPolicy {
  long long every = 0;         // frames between checkpoints; 0 = none
  bool resume = false;         // start from the newest usable checkpoint
  std::filesystem::path dir;   // the checkpoints' folder (a forest's: a subfolder per tree)
};

struct BakeConfig {
  std::filesystem::path out_dir;      // relative output paths resolve here; "" = the working folder
  std::optional<FrameRange> frames;   // the frames to write, within the scene's; none: all of them
  std::optional<Shard> shard;         // a forest's task; none: every tree
  CheckpointPolicy checkpoints;
  std::string generator = treeanim_generator();
  int threads = 0;                    // OpenMP threads; 0 = the OpenMP default
  bool space_check = true;            // refuse a bake whose files need more than their disks' free space
};

// out_dir, --checkpoint-dir ("" = none) => the checkpoints' folder: OUT/checkpoints by default.
std::filesystem::path checkpoint_folder(const std::filesystem::path& out_dir, const std::filesystem::path& given);

// A forest's config, a tree's id => the tree's config: its checkpoints in a folder of their own.
BakeConfig tree_bake_config(const BakeConfig& forest, const std::string& id);

}  // namespace treeanim
