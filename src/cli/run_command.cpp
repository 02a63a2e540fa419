// treeanim run: one tree, or a forest's trees one after another (cli/forest_run.cpp).
#include <omp.h>

#include "cli/bake_tree.h"
#include "cli/commands.h"
#include "cli/forest_run.h"
#include "cli/signals.h"
#include "common/errors.h"

namespace treeanim {

std::pair<long long, long long> parse_frame_range(const std::string& text, long long first,
                                                  long long last) {
  const std::string expected = "--frames '" + text + "': expected START:END with " +
                               std::to_string(first) + " <= START <= END <= " +
                               std::to_string(last) + " (the scene's time.start and time.frames)";
  const size_t colon = text.find(':');
  if (colon == std::string::npos) throw InputError(expected);
  long long start = 0, end = 0;
  try {
    size_t used = 0;
    start = std::stoll(text.substr(0, colon), &used);
    if (used != colon) throw InputError(expected);
    end = std::stoll(text.substr(colon + 1), &used);
    if (used != text.size() - colon - 1) throw InputError(expected);
  } catch (const std::logic_error&) {
    throw InputError(expected);
  }
  if (start < first || end > last || start > end) throw InputError(expected);
  return {start, end};
}

int run_command(const RunRequest& request) {
  install_interrupt_handlers();
  if (request.threads > 0) omp_set_num_threads(request.threads);
  const Scene scene = load_scene(request.scene, request.overrides);
  if (scene.forest) return run_forest(scene, request);
  if (request.shard)
    throw InputError("--shard " + *request.shard + ": shards split the trees of a /forest, and " +
                     request.scene.string() + " has one tree (split its frames with --frames)");
  return bake_tree(scene, request, nullptr).exit_code;
}

}  // namespace treeanim
