#pragma once
// Checkpoints of a bake (docs/checkpoint.md, a contract): the complete SimState after a frame,
// in a small HDF5 file written atomically (temporary + rename), tied to its scene and
// treeanim version by a hash, so a preempted bake continues bit-identically.
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "sim/sim_state.h"

namespace treeanim {

// What ties a checkpoint to its bake.
struct CheckpointKey {
  std::string scene_hash;  // scene_hash() of the resolved scene and the generator (bake/scene_hash.h)
  std::string generator;   // "treeanim <version>"
  bool float_precision = false;  // hsm.precision: the precision of the stored prediction
};

// dir, frame => dir/checkpoint-<frame>.h5
std::filesystem::path checkpoint_path(const std::filesystem::path& dir, long long frame);
// Files named checkpoint-<frame>.h5 in dir => (frame, path), newest (highest frame) first;
// none when dir does not exist.
std::vector<std::pair<long long, std::filesystem::path>> list_checkpoints(const std::filesystem::path& dir);

// A bake's checkpoint folder => InputError when one of this process's inputs (common/input_files.h)
// is there under a name the bake takes for its own checkpoints and journals, which it would
// replace or remove; nothing when the folder does not exist.
void check_checkpoint_folder(const std::filesystem::path& dir);

// A finished bake's checkpoint folder => its checkpoints, frame journals and their temporaries
// removed, then the folder when that empties it. Nothing else is touched: no other file in it,
// nor what stands at `dir` when it is not a folder (a link, a file). Never throws.
void remove_spent_checkpoints(const std::filesystem::path& dir) noexcept;

// A model's sizes => an upper bound of one checkpoint's bytes: the state's vertex arrays (positions,
// velocities and the step prediction's six) and cluster arrays in double, flags, and the HDF5 layout.
double estimated_checkpoint_bytes(size_t vertices, size_t clusters, size_t leaves);

// The state after `frame` => `path`, atomically: a temporary beside it, flushed to disk, then
// renamed. Throws OutputError naming the path.
void write_checkpoint(const std::filesystem::path& path, const SimState& state, long long frame,
                      const CheckpointKey& key);

// A checkpoint => its frame and state. `shape` (e.g. Simulator::initial_state) gives the sizes
// every array must have. Throws InputError naming the file and why: unreadable or damaged,
// another format or version, another scene or treeanim version, arrays of other sizes.
std::pair<long long, SimState> read_checkpoint(const std::filesystem::path& path, const CheckpointKey& key,
                                               const SimState& shape);

}  // namespace treeanim
