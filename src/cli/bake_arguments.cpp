#include "cli/bake_arguments.h"

#include <charconv>
#include <cstdlib>

#include "common/errors.h"
#include "common/message_text.h"

namespace treeanim {

FrameRange parse_frame_range(const std::string& text, long long first, long long last) {
  const std::string expected = "--frames '" + text + "': expected START:END with " +
                               std::to_string(first) + " <= START <= END <= " +
                               std::to_string(last) + " (the scene's time.start and time.frames)";
  const size_t colon = text.find(':');
  if (colon == std::string::npos) throw InputError(expected);
  // Each side a whole integer, nothing around it (stoll skipped leading blanks but not trailing ones).
  auto integer = [&](const char* begin, const char* stop, long long& value) {
    const auto [at, error] = std::from_chars(begin, stop, value);
    if (error != std::errc() || at != stop || begin == stop) throw InputError(expected);
  };
  long long start = 0, end = 0;
  integer(text.data(), text.data() + colon, start);
  integer(text.data() + colon + 1, text.data() + text.size(), end);
  if (start < first || end > last || start > end) throw InputError(expected);
  return {start, end};
}

Shard parse_shard(const std::string& text) {
  std::string expected = "--shard '" + text +
                         "': expected I/N with 0 <= I < N <= 1000000 (farm --tasks' range), the 0-based task "
                         "of N (I may be 'auto', which reads $SLURM_ARRAY_TASK_ID)";
  const size_t slash = text.find('/');
  if (slash == std::string::npos) throw InputError(expected);
  std::string index = text.substr(0, slash);
  if (index == "auto") {
    const char* env = std::getenv("SLURM_ARRAY_TASK_ID");
    if (!env) throw InputError("--shard '" + text + "': SLURM_ARRAY_TASK_ID is not set (not a Slurm array task): give I/N");
    index = env;
    expected += ", and $SLURM_ARRAY_TASK_ID is '" + excerpt(index) + "'";
  }
  const auto parse = [&](const std::string& digits) {
    if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos)
      throw InputError(expected);
    return static_cast<size_t>(std::stoul(digits));
  };
  Shard shard{parse(index), parse(text.substr(slash + 1))};
  // The plan of N tasks holds one list per task: a count past farm's is a slip, not a farm.
  if (shard.count == 0 || shard.count > 1'000'000 || shard.index >= shard.count) throw InputError(expected);
  return shard;
}

BakeConfig bake_config(const RunRequest& request, const Scene& scene) {
  if (scene.forest && request.frames)
    throw InputError("--frames " + *request.frames + ": a forest is split by its trees (--shard I/N), not by frames");
  if (!scene.forest && request.shard)
    throw InputError("--shard " + *request.shard + ": shards split the trees of a /forest, and " +
                     request.scene.string() + " has one tree (split its frames with --frames)");
  BakeConfig config;
  config.out_dir = request.out_dir;
  if (request.frames)
    config.frames = parse_frame_range(*request.frames, scene.time.start, scene.time.start + scene.time.frames - 1);
  if (request.shard) config.shard = parse_shard(*request.shard);
  config.checkpoints = {request.checkpoint_every, request.resume,
                        checkpoint_folder(request.out_dir, request.checkpoint_dir)};
  config.threads = request.threads;
  config.space_check = !request.no_space_check;
  return config;
}

}  // namespace treeanim
