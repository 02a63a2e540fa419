// `treeanim run`'s arguments => the bake's config (cli/bake_arguments.h), with the messages of
// what it refuses.
#include <gtest/gtest.h>

#include <cstdlib>

#include "cli/bake_arguments.h"
#include "common/errors.h"

namespace treeanim {
namespace {

std::string error_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

Scene line_scene(const std::string& extra = "") {
  return load_scene_text(R"({"lsystem": {"axiom": "F", "iterations": 0}, "time": {"start": 2, "frames": 10})" +
                             extra + "}",
                         "line.json", "/scenes", {});
}

TEST(BakeArguments, ParseShard) {
  EXPECT_EQ(parse_shard("3/8").index, 3u);
  EXPECT_EQ(parse_shard("3/8").count, 8u);
  EXPECT_EQ(parse_shard("999999/1000000").count, 1'000'000u);
  for (const char* bad : {"8/8", "1", "-1/4", "a/4", "0/0", "1/", "/4", "15/1000001", "15/999999999"})
    EXPECT_EQ(error_of([&] { parse_shard(bad); }),
              std::string("--shard '") + bad +
                  "': expected I/N with 0 <= I < N <= 1000000 (farm --tasks' range), the 0-based task of N (I may be "
                  "'auto', which reads $SLURM_ARRAY_TASK_ID)");
  setenv("SLURM_ARRAY_TASK_ID", "2", 1);
  EXPECT_EQ(parse_shard("auto/4").index, 2u);
  unsetenv("SLURM_ARRAY_TASK_ID");
  EXPECT_EQ(error_of([] { parse_shard("auto/4"); }),
            "--shard 'auto/4': SLURM_ARRAY_TASK_ID is not set (not a Slurm array task): give I/N");
}

TEST(BakeArguments, ParseFrameRange) {
  const FrameRange range = parse_frame_range("3:5", 2, 11);
  EXPECT_EQ(range.first, 3);
  EXPECT_EQ(range.last, 5);
  for (const char* bad : {"1:5", "3:12", "5:3", "3", "3:x", "x:3", "3:5 "})
    EXPECT_EQ(error_of([&] { parse_frame_range(bad, 2, 11); }),
              std::string("--frames '") + bad +
                  "': expected START:END with 2 <= START <= END <= 11 (the scene's time.start and time.frames)");
}

TEST(BakeArguments, ConfigOfOneTree) {
  RunRequest request;
  request.scene = "line.json";
  request.frames = "4:6";
  request.checkpoint_every = 3;
  request.threads = 2;
  BakeConfig config = bake_config(request, line_scene());
  ASSERT_TRUE(config.frames);
  EXPECT_EQ(config.frames->first, 4);
  EXPECT_EQ(config.frames->last, 6);
  EXPECT_FALSE(config.shard);
  EXPECT_EQ(config.checkpoints.every, 3);
  EXPECT_EQ(config.checkpoints.dir, "checkpoints");  // no -o: in the working folder
  EXPECT_EQ(config.generator, treeanim_generator());
  EXPECT_EQ(config.threads, 2);
  request.out_dir = "out";
  EXPECT_EQ(bake_config(request, line_scene()).checkpoints.dir, "out/checkpoints");
  request.checkpoint_dir = "elsewhere";
  EXPECT_EQ(bake_config(request, line_scene()).checkpoints.dir, "elsewhere");
  request.shard = "0/2";
  EXPECT_EQ(error_of([&] { bake_config(request, line_scene()); }),
            "--shard 0/2: shards split the trees of a /forest, and line.json has one tree (split its frames with "
            "--frames)");
}

TEST(BakeArguments, ConfigOfAForest) {
  const Scene forest =
      line_scene(R"(, "forest": {"variants": [{"name": "one"}], "trees": [{"id": "a", "variant": "one", "position": [0, 0, 0]}]})");
  RunRequest request;
  request.shard = "1/3";
  const BakeConfig config = bake_config(request, forest);
  ASSERT_TRUE(config.shard);
  EXPECT_EQ(config.shard->index, 1u);
  EXPECT_EQ(config.shard->count, 3u);
  request.frames = "2:3";
  EXPECT_EQ(error_of([&] { bake_config(request, forest); }),
            "--frames 2:3: a forest is split by its trees (--shard I/N), not by frames");
}

}  // namespace
}  // namespace treeanim
