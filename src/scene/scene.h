#pragma once
// Stage entry point of scene/: a scene file (+ --set overrides) => validated options of every
// stage and the resolved scene JSON (defaults filled in) that outputs record.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "lsystem/lsystem_options.h"
#include "output/output_options.h"
#include "scene/forest.h"
#include "scene/scene_reader.h"
#include "sim/sim_options.h"
#include "sim/wind_volume.h"
#include "tree/tree_options.h"

namespace treeanim {

// Scene section /time.
struct TimeOptions {
  double fps = 24;          // frames per second
  long long frames = 120;   // frames simulated (and written)
  long long start = 0;      // index of the first frame; frame k is at time k / fps
  int substeps = 2;         // solver steps per frame (<= 1% error with the default hsm, docs/benchmarks.md)
  bool loop = false;        // a seamless loop: periodic wind, warm-up, one period baked
};

struct Scene {
  std::filesystem::path file;  // the scene file ("" when loaded from text)
  Json resolved;               // the scene with every default filled in
  uint64_t seed = 1;           // /seed, the default of every per-purpose seed
  LsystemOptions lsystem;      // /lsystem (a forest whose variants all have their own may leave it out)
  TreeOptions tree;
  HsmOptions hsm;
  WindOptions wind;
  TimeOptions time;
  std::vector<OutputOptions> outputs;
  std::optional<Forest> forest;  // /forest: many trees; none = the one tree of /lsystem
  // A forest's tree (tree_scene): "forest tree 'ID' (its scale S)", for the messages that its own
  // scale may explain; "" for a lone tree.
  std::string forest_tree;
  std::optional<VolumeSummary> volume;  // /wind/volume checked over the bake's times: what `info` prints
  // The files the scene names (grammars, views, wind series, leaf meshes, volume patterns),
  // sorted, each once: their contents key a bake (bake_key), as the resolved scene holds only paths.
  std::vector<std::filesystem::path> input_paths;
  // The frame files of /wind/volume over the bake's times, in order: their sizes and times key
  // a bake (a sequence may hold gigabytes, which the key does not read again).
  std::vector<std::filesystem::path> volume_frames;
};

// Where one override put its value: the JSON pointer it set, and the outermost value it made
// (an object or array the document did not have on the way there; else the pointer it set).
struct AppliedOverride {
  std::string target, made;
};
// Applies one "--set a.b.c=VALUE" override to a scene document (VALUE parsed as JSON, else a
// string; JSON nested too deep, with a repeated key or an out-of-range number is refused). Missing
// intermediate objects (arrays where the path indexes them) are created. Throws InputError on a
// malformed override.
AppliedOverride apply_override(Json& document, const std::string& assignment);

// Loads, overrides, validates. Errors: InputError "file: /pointer: message" (exit 2).
Scene load_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides);
// Same from text; relative paths resolve against base_dir. `name` prefixes messages.
Scene load_scene_text(const std::string& text, const std::string& name,
                      const std::filesystem::path& base_dir,
                      const std::vector<std::string>& overrides);

// A forest's tree `index` => its own one-tree scene: its variant's grammar with the tree's seed,
// the tree options at its scale, {tree} in output paths replaced by its id, and as resolved
// JSON the forest reduced to this tree (what its outputs record; a scene that bakes it again).
Scene tree_scene(const Scene& forest_scene, size_t index);

}  // namespace treeanim
