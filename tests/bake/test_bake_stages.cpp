// The stages of one tree's bake (bake/bake_tree.h): plan, start, warm up, replay, run, finish.
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "bake/bake_tree.h"
#include "bake/checkpoint.h"
#include "bake/prepare_tree.h"
#include "common/input_files.h"
#include "sim/simulator.h"
#include "temp_folder_test.h"

namespace treeanim {
namespace {

namespace fs = std::filesystem;

// Three unit segments straight up, 5 frames from frame 10, one HDF5 output.
const char* kLine = R"({
  "lsystem": {"axiom": "FFF", "iterations": 0},
  "time": {"fps": 24, "start": 10, "frames": 5, "substeps": 2},
  "wind": {"keys": [{"time": 0, "speed": 4, "direction": [1, 0, 0]}]},
  "outputs": [{"format": "hdf5", "path": "bake.h5"}]
})";

std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// What a stage wrote to its notes.
class Notes {
 public:
  Notes() : file_(std::tmpfile()) {}
  ~Notes() { std::fclose(file_); }
  std::FILE* file() const { return file_; }
  std::string text() const {
    std::fflush(file_);
    std::rewind(file_);
    std::string text;
    for (int c; (c = std::fgetc(file_)) != EOF;) text += char(c);
    return text;
  }

 private:
  std::FILE* file_;
};

class BakeStages : public TempFolderTest {
 protected:
  BakeStages() : TempFolderTest("treeanim-bake") {}

  Scene scene(const std::vector<std::string>& overrides = {}) const {
    return load_scene_text(kLine, "line.json", dir_, overrides);
  }
  BakeConfig config() const {
    BakeConfig config;
    config.out_dir = dir_ / "out";
    config.checkpoints.dir = dir_ / "checkpoints";
    return config;
  }
};

TEST_F(BakeStages, PlanOfAFrameRange) {
  const Scene line = scene({"time.loop=true"});
  BakeConfig part = config();
  part.frames = FrameRange{12, 13};
  const BakePlan plan = plan_bake(line, part);
  EXPECT_EQ(plan.first, 10);
  EXPECT_EQ(plan.last, 14);
  EXPECT_EQ(plan.written.first, 12);
  EXPECT_EQ(plan.written.count(), 2);
  EXPECT_TRUE(plan.loop);
  EXPECT_FALSE(plan.closes_loop);  // a part of a loop does not close it
  EXPECT_TRUE(plan.use_checkpoints);  // --frames starts from a checkpoint at or before its first frame
  EXPECT_EQ(plan.key.scene_hash, bake_key(line, treeanim_generator()));
  EXPECT_EQ(plan.key.generator.rfind("treeanim ", 0), 0u);
  EXPECT_EQ(frame_time(plan, 12), 12.0 * (1.0 / 24));
  const BakeInfo info = bake_info(line, plan, TreeModel(), nullptr);
  EXPECT_EQ(info.frame_start, 12);
  EXPECT_EQ(info.frame_count, 2);
  EXPECT_FALSE(info.loop);
  EXPECT_EQ(info.loop_end_time, 15.0 / 24);

  const BakePlan whole = plan_bake(line, config());
  EXPECT_EQ(whole.written.first, 10);
  EXPECT_EQ(whole.written.last, 14);
  EXPECT_TRUE(whole.closes_loop);
  EXPECT_FALSE(whole.use_checkpoints);
}

// The scene names its grammar and wind series by path: their bytes are part of the key, so a
// checkpoint of the old files is not resumed with the new ones.
TEST_F(BakeStages, TheKeyHoldsWhatTheNamedFilesHold) {
  std::ofstream(dir_ / "g.lsys") << "Axiom: FF\n";
  std::ofstream(dir_ / "wind.csv") << "time,speed,dx,dy,dz\n0,4,1,0,0\n";
  const char* scene = R"({"lsystem": {"grammar": "g.lsys"}, "time": {"frames": 2},
    "wind": {"file": "wind.csv"}, "outputs": []})";
  auto key = [&] { return bake_key(load_scene_text(scene, "s.json", dir_, {}), treeanim_generator()); };
  const std::string first = key();
  EXPECT_EQ(key(), first);
  std::ofstream(dir_ / "g.lsys") << "Axiom: FFF\n";
  const std::string grammar = key();
  EXPECT_NE(grammar, first);
  std::ofstream(dir_ / "wind.csv") << "time,speed,dx,dy,dz\n0,5,1,0,0\n";
  EXPECT_NE(key(), grammar);
  std::ofstream(dir_ / "g.lsys") << "Axiom: FF\n";
  std::ofstream(dir_ / "wind.csv") << "time,speed,dx,dy,dz\n0,4,1,0,0\n";
  EXPECT_EQ(key(), first);  // the same bytes, the same bake
}

TEST_F(BakeStages, TheKeyHoldsWhatTheGrammarReadsInTurn) {
  // An #include, a data file fopen reads, and a view file's surface, which cpfg leaves out
  // while its file is missing: each edit is a new bake.
  std::ofstream(dir_ / "g.l") << "#include \"more.l\"\nStart: {fp = fopen(\"data.txt\", \"r\");}\nAxiom: F\n";
  std::ofstream(dir_ / "more.l") << "#define N 1\n";
  std::ofstream(dir_ / "data.txt") << "1\n";
  std::ofstream(dir_ / "v.v") << "surface: L leaf.s 1\n";
  const char* scene = R"({"lsystem": {"grammar": "g.l", "view": "v.v"}, "time": {"frames": 2}, "outputs": []})";
  auto key = [&] { return bake_key(load_scene_text(scene, "s.json", dir_, {}), treeanim_generator()); };
  const std::string first = key();
  std::ofstream(dir_ / "more.l") << "#define N 2\n";
  const std::string included = key();
  EXPECT_NE(included, first);
  std::ofstream(dir_ / "data.txt") << "2\n";
  const std::string data = key();
  EXPECT_NE(data, included);
  fs::copy_file(fs::path(TREEANIM_SOURCE_DIR) / "tests/data/cpfg/leaf.s", dir_ / "leaf.s");
  EXPECT_NE(key(), data);
  fs::remove(dir_ / "leaf.s");
  EXPECT_EQ(key(), data);
}

// A glTF leaf keeps its vertices in a buffer file it names: that file is an input as the mesh
// is (no output may replace it), and an edited buffer is a new bake.
TEST_F(BakeStages, TheKeyHoldsTheFilesALeafMeshNames) {
  auto write_buffer = [&](float width) {
    const float positions[12] = {-width, 0.5f, 0, 0, 0, 0, width, 0.5f, 0, 0, 1, 0};
    const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
    std::ofstream out(dir_ / "leaf.bin", std::ios::binary);
    out.write(reinterpret_cast<const char*>(positions), sizeof positions);
    out.write(reinterpret_cast<const char*>(indices), sizeof indices);
  };
  write_buffer(0.5f);
  std::ofstream(dir_ / "leaf.gltf") << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "buffers": [{"uri": "leaf.bin", "byteLength": 60}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.5, 0, 0], "max": [0.5, 1, 0]},
                  {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}]})";
  const char* scene = R"({"lsystem": {"axiom": "F", "iterations": 0}, "tree": {"leaf": {"mesh": "leaf.gltf"}},
    "time": {"frames": 2}, "outputs": []})";
  auto key = [&] { return bake_key(load_scene_text(scene, "s.json", dir_, {}), treeanim_generator()); };
  const std::string first = key();
  EXPECT_FALSE(input_file_at(dir_ / "leaf.bin").empty());
  write_buffer(0.25f);
  EXPECT_NE(key(), first);
  write_buffer(0.5f);
  EXPECT_EQ(key(), first);
}

TEST_F(BakeStages, StartFreshThenFromACheckpoint) {
  const Scene line = scene();
  BakeConfig resume = config();
  resume.checkpoints.resume = true;
  const BakePlan plan = plan_bake(line, resume);
  const PreparedTree tree = prepare_tree(line);
  Simulator simulator(tree.model, line.hsm, line.wind, plan.frame_dt, line.time.substeps);
  const JournalLayout layout = journal_layout(plan, tree.model, false);
  Notes notes;
  BakeStart fresh = start_bake(plan, layout, simulator, notes.file());
  EXPECT_EQ(fresh.frame, 10);
  EXPECT_TRUE(fresh.checkpoint.empty());
  EXPECT_EQ(fresh.state.time, frame_time(plan, 10));
  EXPECT_EQ(notes.text(), "treeanim: no usable checkpoint in " + (dir_ / "checkpoints").string() +
                              ": baking from frame 10\n");

  // A checkpoint after the first written frame needs the journal of the frames before it: none here.
  simulator.advance_frame(fresh.state, 11);
  fs::create_directories(dir_ / "checkpoints");
  const fs::path checkpoint = checkpoint_path(dir_ / "checkpoints", 11);
  write_checkpoint(checkpoint, fresh.state, 11, plan.key);
  Notes skipped;
  EXPECT_EQ(start_bake(plan, layout, simulator, skipped.file()).frame, 10);
  EXPECT_NE(skipped.text().find("treeanim: not resuming from " + checkpoint.string() + ": "), std::string::npos)
      << skipped.text();

  // --frames 11:14: the checkpoint at its first frame is where it starts, no journal needed.
  BakeConfig part = config();
  part.frames = FrameRange{11, 14};
  const BakePlan part_plan = plan_bake(line, part);
  Notes resumed;
  const BakeStart start = start_bake(part_plan, journal_layout(part_plan, tree.model, false), simulator, resumed.file());
  EXPECT_EQ(start.frame, 11);
  EXPECT_EQ(start.checkpoint, checkpoint);
  EXPECT_EQ(start.state.positions, fresh.state.positions);
  EXPECT_EQ(resumed.text(), "treeanim: resuming at frame 11 from " + checkpoint.string() + "\n");

  // --resume of frames 10:10 only: the checkpoint after them is passed over, and said so.
  BakeConfig first_only = resume;
  first_only.frames = FrameRange{10, 10};
  const BakePlan first_plan = plan_bake(line, first_only);
  Notes passed;
  EXPECT_EQ(start_bake(first_plan, journal_layout(first_plan, tree.model, false), simulator, passed.file()).frame, 10);
  EXPECT_EQ(passed.text(), "treeanim: not resuming from " + checkpoint.string() +
                               ": it is after frame 10, the last to write\ntreeanim: no usable checkpoint in " +
                               (dir_ / "checkpoints").string() + ": baking from frame 10\n");
}

TEST_F(BakeStages, RunAFewFramesAndFinish) {
  const Scene line = scene();
  const BakeConfig whole = config();
  const BakePlan plan = plan_bake(line, whole);
  const PreparedTree tree = prepare_tree(line);
  BakeFrames frames(line, whole, plan, tree.model, nullptr);
  Simulator simulator(tree.model, line.hsm, line.wind, plan.frame_dt, line.time.substeps);
  const JournalLayout layout = journal_layout(plan, tree.model, frames.outputs.wants_velocities());
  BakeStart start = start_bake(plan, layout, simulator, nullptr);
  ThreadGovernor governor(1, [](const std::string&) {});  // the team as it is
  EXPECT_EQ(warm_up(plan, simulator, start, nullptr, governor).periods, 0);  // not a loop
  replay_journal(plan, layout, start, frames, nullptr);
  std::vector<long long> done;
  BakeLog log;
  log.frame_done = [&](long long frames_done) { done.push_back(frames_done); };
  ASSERT_EQ(run_frames(plan, simulator, start, frames, nullptr, log, governor), 0);
  EXPECT_EQ(done, (std::vector<long long>{1, 2, 3, 4, 5}));
  const TreeBakeResult result = finish_bake(plan, start, {}, frames, log);
  EXPECT_EQ(result.written.first, 10);
  EXPECT_EQ(result.written.count(), 5);
  EXPECT_EQ(result.substeps, 4 * 2);
  ASSERT_EQ(result.files.size(), 1u);
  EXPECT_EQ(result.files[0], std::vector<fs::path>{dir_ / "out" / "bake.h5"});
  EXPECT_TRUE(fs::is_regular_file(dir_ / "out" / "bake.h5"));
  EXPECT_FALSE(result.loop);
  EXPECT_TRUE(result.bounds.isEmpty());  // a lone tree's: nothing reads them
}

TEST_F(BakeStages, FinishGivesTheBoundsInTheWorld) {
  const Scene line = scene();
  const TreePlacement origin = make_tree_placement(Eigen::Vector3d::Zero(), 0);
  const TreeBakeResult own = bake_tree(line, config(), &origin, BakeLog{});
  const TreePlacement placement = make_tree_placement(Eigen::Vector3d(5, 0, -2), 0);
  const TreeBakeResult placed = bake_tree(line, config(), &placement, BakeLog{});
  // The stem stands at the origin, three units tall.
  EXPECT_NEAR(own.bounds.min().y(), 0.0, 1e-3);
  EXPECT_GT(own.bounds.max().y(), 2.9);
  EXPECT_NEAR(placed.bounds.min().x(), own.bounds.min().x() + 5, 1e-4);
  EXPECT_NEAR(placed.bounds.max().z(), own.bounds.max().z() - 2, 1e-4);
  EXPECT_NEAR(placed.bounds.max().y(), own.bounds.max().y(), 1e-4);
}

TEST_F(BakeStages, TheWorldBoundsHoldTheTurnedVerticesTightly) {
  // A point cache holds the frames in the tree's own frame; turned by 45° they give the box
  // exactly, where the own frame's box turned with the tree would be wider.
  const Scene line = scene({R"(outputs=[{"format": "pc2", "path": "bake.pc2"}])"});
  const TreePlacement placement = make_tree_placement(Eigen::Vector3d(3, 0, 1), 45);
  const TreeBakeResult placed = bake_tree(line, config(), &placement, BakeLog{});
  const std::string cache = slurp(dir_ / "out" / "bake.pc2");
  int32_t points = 0, samples = 0;
  std::memcpy(&points, cache.data() + 16, 4);
  std::memcpy(&samples, cache.data() + 28, 4);
  ASSERT_EQ(cache.size(), 32 + size_t(points) * samples * 12);
  Eigen::AlignedBox3d world;
  for (size_t k = 0; k < size_t(points) * samples; ++k) {
    float x[3];
    std::memcpy(x, cache.data() + 32 + 12 * k, 12);
    world.extend(placement.rotation * Eigen::Vector3d(x[0], x[1], x[2]) + placement.translation);
  }
  EXPECT_LT((placed.bounds.min() - world.min()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((placed.bounds.max() - world.max()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST_F(BakeStages, AResumedBakeWritesTheSameBytes) {
  // A point cache: an HDF5 file's bytes hold the time it was written.
  const Scene line = scene({R"(outputs=[{"format": "pc2", "path": "bake.pc2"}])"});
  BakeConfig checkpointed = config();
  checkpointed.checkpoints.every = 2;
  std::vector<long long> totals;
  BakeLog log;
  log.frames_begin = [&](long long total) { totals.push_back(total); };
  ASSERT_EQ(bake_tree(line, checkpointed, nullptr, log).exit_code, 0);
  const std::string whole = slurp(dir_ / "out" / "bake.pc2");
  ASSERT_FALSE(whole.empty());
  EXPECT_TRUE(fs::exists(checkpoint_path(dir_ / "checkpoints", 14)));
  // From the newest checkpoint (frame 14): the journal gives the frames before it back.
  checkpointed.checkpoints.resume = true;
  Notes notes;
  log.notes = notes.file();
  const TreeBakeResult resumed = bake_tree(line, checkpointed, nullptr, log);
  EXPECT_EQ(resumed.substeps, 0);
  EXPECT_EQ(totals, (std::vector<long long>{5, 1}));
  EXPECT_EQ(notes.text(), "treeanim: resuming at frame 14 from " +
                              checkpoint_path(dir_ / "checkpoints", 14).string() + "\n");
  EXPECT_EQ(slurp(dir_ / "out" / "bake.pc2"), whole);
}

// The journal holds the written frames a resume replays, those before the last checkpoint,
// and a bake that writes no checkpoint (--checkpoint-every past its frames) writes none.
TEST_F(BakeStages, TheJournalHoldsTheFramesBeforeTheLastCheckpoint) {
  const Scene line = scene({R"(outputs=[{"format": "pc2", "path": "bake.pc2"}])"});  // frames 10 to 14
  const fs::path journal = journal_path(dir_ / "checkpoints", 10);
  BakeConfig checkpointed = config();
  checkpointed.checkpoints.every = 3;
  ASSERT_EQ(bake_tree(line, checkpointed, nullptr, BakeLog{}).exit_code, 0);
  const BakePlan plan = plan_bake(line, checkpointed);
  EXPECT_EQ(last_checkpoint(plan), 13);
  EXPECT_TRUE(fs::exists(checkpoint_path(dir_ / "checkpoints", 13)));
  const PreparedTree tree = prepare_tree(line);
  EXPECT_EQ(FrameJournal::open(journal, journal_layout(plan, tree.model, false)).size(), 3);  // frames 10 to 12
  // --frames 14:14 starts after the last checkpoint: nothing to journal, the checkpoint still written.
  fs::remove_all(dir_ / "checkpoints");
  BakeConfig after = checkpointed;
  after.frames = FrameRange{14, 14};
  ASSERT_EQ(bake_tree(line, after, nullptr, BakeLog{}).exit_code, 0);
  EXPECT_TRUE(fs::exists(checkpoint_path(dir_ / "checkpoints", 13)));
  EXPECT_FALSE(fs::exists(journal_path(dir_ / "checkpoints", 14)));
  fs::remove_all(dir_ / "checkpoints");
  checkpointed.checkpoints.every = 5;
  EXPECT_EQ(last_checkpoint(plan_bake(line, checkpointed)), 10);
  ASSERT_EQ(bake_tree(line, checkpointed, nullptr, BakeLog{}).exit_code, 0);
  EXPECT_TRUE(fs::is_regular_file(dir_ / "out" / "bake.pc2"));
  EXPECT_FALSE(fs::exists(journal));
}

TEST_F(BakeStages, ASampledBakeResumedFromAnEarlierCheckpointWritesTheSameBytes) {
  // The skinned GLB's keys are the clusters' motions: the journal replays them too.
  const Scene line = scene({R"(outputs=[{"format": "pc2", "path": "bake.pc2"},
                                        {"format": "skinned_glb", "path": "bake.glb"}])",
                            R"(hsm.particles="samples")", "lsystem.axiom=\"FFF[+FF]FF\""});
  BakeConfig checkpointed = config();
  checkpointed.checkpoints.every = 2;
  ASSERT_EQ(bake_tree(line, checkpointed, nullptr, BakeLog{}).exit_code, 0);
  const std::string whole = slurp(dir_ / "out" / "bake.pc2"), skinned = slurp(dir_ / "out" / "bake.glb");
  ASSERT_FALSE(whole.empty());
  // From frame 12: frames 13 and 14 simulated again from the samples' checkpoint.
  fs::remove(checkpoint_path(dir_ / "checkpoints", 14));
  checkpointed.checkpoints.resume = true;
  const TreeBakeResult resumed = bake_tree(line, checkpointed, nullptr, BakeLog{});
  EXPECT_EQ(resumed.substeps, 2 * 2);
  EXPECT_EQ(slurp(dir_ / "out" / "bake.pc2"), whole);
  EXPECT_EQ(slurp(dir_ / "out" / "bake.glb"), skinned);
  // The samples' state is what a checkpoint holds: smaller than the mesh's.
  BakeConfig vertices = config();
  vertices.checkpoints.every = 2;
  vertices.checkpoints.dir = dir_ / "vertex-checkpoints";
  const Scene mesh = scene({R"(outputs=[{"format": "pc2", "path": "mesh.pc2"}])", "lsystem.axiom=\"FFF[+FF]FF\""});
  ASSERT_EQ(bake_tree(mesh, vertices, nullptr, BakeLog{}).exit_code, 0);
  EXPECT_LT(fs::file_size(checkpoint_path(dir_ / "checkpoints", 12)),
            fs::file_size(checkpoint_path(dir_ / "vertex-checkpoints", 12)));
}

TEST_F(BakeStages, ASampledBakePlacesItsMeshBesideTheSolverWithTheSameBytes) {
  // One solver thread leaves a core to the frame thread; every core taken, the mesh is placed
  // between frames. Checkpoints make the frame thread finish; the HDF5 output's velocities
  // come from its copy of the state.
  if (omp_get_num_procs() < 2) GTEST_SKIP() << "one core: no frame thread";
  const Scene line = scene({R"(outputs=[{"format": "pc2", "path": "bake.pc2"},
                                        {"format": "skinned_glb", "path": "bake.glb"},
                                        {"format": "hdf5", "path": "bake.h5", "velocities": true}])",
                            R"(hsm.particles="samples")", "lsystem.axiom=\"FFF[+FF]FF\""});
  std::vector<std::string> pc2, glb, h5;
  for (const int threads : {1, omp_get_num_procs()}) {
    BakeConfig beside = config();
    beside.threads = threads;
    beside.checkpoints.every = 2;
    beside.checkpoints.dir = dir_ / ("checkpoints-" + std::to_string(threads));
    ASSERT_EQ(bake_tree(line, beside, nullptr, BakeLog{}).exit_code, 0);
    pc2.push_back(slurp(dir_ / "out" / "bake.pc2"));
    glb.push_back(slurp(dir_ / "out" / "bake.glb"));
    h5.push_back(slurp(dir_ / "out" / "bake.h5"));
  }
  omp_set_num_threads(omp_get_num_procs());
  ASSERT_FALSE(pc2[0].empty());
  EXPECT_EQ(pc2[0], pc2[1]);
  EXPECT_EQ(glb[0], glb[1]);
  EXPECT_EQ(h5[0], h5[1]);
}

TEST_F(BakeStages, ASampledBakeWithoutOutputsStillSimulates) {
  const Scene line = scene({"outputs=[]", R"(hsm.particles="samples")"});
  const TreePlacement origin = make_tree_placement(Eigen::Vector3d::Zero(), 0);
  const TreeBakeResult result = bake_tree(line, config(), &origin, BakeLog{});
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_EQ(result.substeps, 4 * 2);
  EXPECT_GT(result.bounds.max().y(), 2.9);  // the samples' own bounds
}

TEST_F(BakeStages, ALoopWarmsUpWholePeriods) {
  const Scene line = scene({"time.loop=true"});
  const BakePlan plan = plan_bake(line, config());
  const PreparedTree tree = prepare_tree(line);
  Simulator simulator(tree.model, line.hsm, line.wind, plan.frame_dt, line.time.substeps);
  BakeStart start = start_bake(plan, journal_layout(plan, tree.model, false), simulator, nullptr);
  Notes notes;
  ThreadGovernor governor(1, [](const std::string&) {});
  const LoopWarmup warmup = warm_up(plan, simulator, start, notes.file(), governor);
  EXPECT_GE(warmup.periods, 1);
  EXPECT_LE(warmup.periods, kMaxLoopWarmupPeriods);
  EXPECT_EQ(notes.text().rfind("treeanim: loop warm-up period 1: the state changed by ", 0), 0u) << notes.text();
  EXPECT_EQ(warmup.converged, warmup.change <= kLoopRepeatChange);
}

}  // namespace
}  // namespace treeanim
