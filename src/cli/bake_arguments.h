#pragma once
// `treeanim run`'s arguments => the typed config of its bake (bake/bake_config.h): the only place
// that reads --frames and --shard.
#include <string>
#include <utility>

#include "bake/bake_config.h"
#include "cli/commands.h"
#include "scene/scene.h"

namespace treeanim {

// "START:END" => inclusive range within [first, last]; throws InputError naming --frames.
FrameRange parse_frame_range(const std::string& text, long long first, long long last);

// "I/N" (or "auto/N": I from $SLURM_ARRAY_TASK_ID) => shard; InputError unless 0 <= I < N.
Shard parse_shard(const std::string& text);

// The request and its loaded scene => the bake's config. Throws InputError for --frames of a
// forest, --shard of one tree, and a malformed or out-of-range value of either.
BakeConfig bake_config(const RunRequest& request, const Scene& scene);

}  // namespace treeanim
