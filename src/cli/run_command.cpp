// treeanim run: one tree, or a forest's trees one after another (bake/bake_forest.h).
#include <cstdio>

#include "bake/bake_forest.h"
#include "bake/bake_tree.h"
#include "bake/forest_tasks.h"
#include "bake/signals.h"
#include "cli/bake_arguments.h"
#include "cli/bake_printer.h"
#include "cli/commands.h"
#include "common/message_text.h"

namespace treeanim {

int run_command(const RunRequest& request) {
  install_interrupt_handlers();
  const Scene scene = load_scene(request.scene, request.overrides);
  const BakeConfig config = bake_config(request, scene);
  if (!request.checkpoint_dir.empty() && request.checkpoint_every <= 0 && !request.resume && !request.frames)
    std::fprintf(stderr, "treeanim: note: --checkpoint-dir %s is not used: only --checkpoint-every, --resume and "
                         "--frames write or read checkpoints\n",
                 printable_text(request.checkpoint_dir.string()).c_str());
  BakePrinter printer(scene, config, request.scene, request.overrides, request.verbosity);
  if (!scene.forest) return bake_tree(scene, config, nullptr, printer.log()).exit_code;
  const std::vector<size_t> trees = shard_trees(scene, config.shard, printer.log().trees_passed);
  printer.shard_begins(trees);
  const ForestBakeResult result = bake_forest(scene, config, trees, printer.log());
  if (result.exit_code == 0) printer.forest_baked(result);
  return result.exit_code;
}

}  // namespace treeanim
