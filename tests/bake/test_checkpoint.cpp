// Checkpoint files and the frame journal (docs/checkpoint.md): a state written and read back
// into a fresh Simulator continues bit-identically; a checkpoint of another scene, a damaged
// one and one of another tree are refused with the reason.
#include <unistd.h>

#include <gtest/gtest.h>
#include <hdf5.h>

#include <cstring>
#include <fstream>

#include "bake/checkpoint.h"
#include "bake/frame_journal.h"
#include "bake/scene_hash.h"
#include "common/errors.h"
#include "common/input_files.h"
#include "sim/simulator.h"
#include "../sim/grown_tree.h"

namespace treeanim {
namespace {

namespace fs = std::filesystem;

// A fresh folder for one test (per process: ctest runs tests side by side), removed at its end.
struct ScratchDir {
  fs::path path;
  explicit ScratchDir(const std::string& name)
      : path(fs::temp_directory_path() / ("treeanim-test-checkpoint-" + std::to_string(::getpid()) + "-" + name)) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

// f() => the message of the InputError it throws, "" when it throws none.
template <typename F>
std::string input_error(F f) {
  try {
    f();
    return "";
  } catch (const InputError& e) {
    return e.what();
  }
}

// Rising from calm to 20 m/s (6 m/s gusts) at 1 s, calm again from 1.1 s.
WindOptions gale() {
  WindOptions wind;
  wind.keys = {{0, 0, {1, 0, 0.2}, 0}, {1.0, 20, {1, 0, 0.2}, 6}, {1.1, 0, {1, 0, 0.2}, 0}};
  return wind;
}

HsmOptions detaching_and_sleeping(Precision precision) {
  HsmOptions options;
  options.precision = precision;
  options.leaf_detach_force = 0.05;
  options.damping_ratio = 1;
  options.sleep_velocity = 0.01;
  options.sleep_distance = 0.01;
  return options;
}

template <typename T>
bool same_bytes(const T& a, const T& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), sizeof(*a.data()) * a.size()) == 0;
}

TEST(Checkpoint, RoundTripThroughTheFileContinuesBitIdentically) {
  const TreeModel model = testing::grown_tree(5, 2, 4);
  const ScratchDir scratch("roundtrip");
  const fs::path& dir = scratch.path;
  for (Precision precision : {Precision::kDouble, Precision::kFloat}) {
    SCOPED_TRACE(precision == Precision::kFloat ? "float" : "double");
    const HsmOptions options = detaching_and_sleeping(precision);
    const CheckpointKey key{"fnv1a64:0123456789abcdef", "treeanim test", precision == Precision::kFloat};
    Simulator whole(model, options, gale(), 1.0 / 24, 3);
    SimState state = whole.initial_state(0);
    // Saved mid-detachment (frame 12) and once the tree sleeps with leaves in the air (60).
    std::vector<std::pair<int, SimState>> saved;
    for (int f = 1; f <= 72; ++f) {
      whole.advance_frame(state, f);
      if (f == 12 || f == 60) {
        write_checkpoint(checkpoint_path(dir, f), state, f, key);
        saved.emplace_back(f, state);
      }
    }
    for (const auto& [frame, copy] : saved) {
      Simulator fresh(model, options, gale(), 1.0 / 24, 3);
      auto [stored_frame, loaded] = read_checkpoint(checkpoint_path(dir, frame), key, fresh.initial_state(0));
      EXPECT_EQ(stored_frame, frame);
      EXPECT_TRUE(same_bytes(loaded.positions, copy.positions));
      EXPECT_EQ(loaded.leaf_attached, copy.leaf_attached);
      EXPECT_EQ(loaded.island_asleep, copy.island_asleep);
      for (int f = frame + 1; f <= 72; ++f) fresh.advance_frame(loaded, f);
      EXPECT_TRUE(same_bytes(loaded.positions, state.positions)) << "from frame " << frame;
      EXPECT_TRUE(same_bytes(loaded.velocities, state.velocities)) << "from frame " << frame;
      EXPECT_EQ(loaded.leaf_attached, state.leaf_attached);
    }
    EXPECT_GT(std::count(saved[0].second.leaf_attached.begin(), saved[0].second.leaf_attached.end(), 0), 0);
    EXPECT_GT(std::count(saved[1].second.island_asleep.begin(), saved[1].second.island_asleep.end(), 1), 0);
  }
  EXPECT_EQ(list_checkpoints(dir).front().first, 60);
  EXPECT_EQ(list_checkpoints(dir).size(), 2u);
}

TEST(Checkpoint, RefusesAnotherSceneADamagedFileAndAnotherTree) {
  const TreeModel model = testing::grown_tree(4, 1, 4);
  const ScratchDir scratch("refuse");
  const fs::path& dir = scratch.path;
  Simulator sim(model, HsmOptions{}, gale(), 1.0 / 24, 2);
  const SimState state = sim.initial_state(0);
  const CheckpointKey key{scene_hash("{}", "treeanim 1"), "treeanim 1", false};
  write_checkpoint(checkpoint_path(dir, 5), state, 5, key);
  const CheckpointKey other{scene_hash("{\"seed\": 2}", "treeanim 1"), "treeanim 1", false};
  EXPECT_NE(key.scene_hash, other.scene_hash);
  EXPECT_NE(input_error([&] { read_checkpoint(checkpoint_path(dir, 5), other, state); })
                .find("written for another scene or treeanim version"),
            std::string::npos);
  const CheckpointKey newer{key.scene_hash, "treeanim 2", false};
  EXPECT_NE(input_error([&] { read_checkpoint(checkpoint_path(dir, 5), newer, state); }).find("treeanim 2"),
            std::string::npos);

  std::ofstream(checkpoint_path(dir, 6), std::ios::binary) << "not HDF5";
  EXPECT_EQ(input_error([&] { read_checkpoint(checkpoint_path(dir, 6), key, state); }),
            checkpoint_path(dir, 6).string() +
                ": not a readable checkpoint: not an HDF5 file (damaged, or not written by treeanim)");

  const TreeModel bigger = testing::grown_tree(5, 1, 4);
  Simulator other_tree(bigger, HsmOptions{}, gale(), 1.0 / 24, 2);
  EXPECT_NE(input_error([&] { read_checkpoint(checkpoint_path(dir, 5), key, other_tree.initial_state(0)); })
                .find("the checkpoint belongs to another tree"),
            std::string::npos);
  EXPECT_TRUE(list_checkpoints(dir / "missing").empty());
}

// One value of a dataset changed in place, the file still HDF5 (a disk's silent damage): the
// digest of the state finds it, where the bake resumed from the wrong state and wrote it.
TEST(Checkpoint, RefusesAStateThatNoLongerMatchesItsDigest) {
  const TreeModel model = testing::grown_tree(4, 1, 4);
  const ScratchDir scratch("digest");
  for (const auto& [dataset, precision] : {std::pair{"/state/positions", Precision::kDouble},
                                           std::pair{"/state/prediction_velocity", Precision::kDouble},
                                           std::pair{"/state/prediction_velocity", Precision::kFloat}}) {
    SCOPED_TRACE(std::string(dataset) + (precision == Precision::kFloat ? " (float)" : " (double)"));
    HsmOptions options;
    options.precision = precision;
    Simulator sim(model, options, gale(), 1.0 / 24, 2);
    SimState state = sim.initial_state(0);
    for (int f = 1; f <= 30; ++f) sim.advance_frame(state, f);
    const CheckpointKey key{scene_hash("{}", "treeanim 1"), "treeanim 1", precision == Precision::kFloat};
    const fs::path path = checkpoint_path(scratch.path, 30);
    write_checkpoint(path, state, 30, key);
    EXPECT_EQ(read_checkpoint(path, key, state).first, 30);
    const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(file, 0);
    const hid_t data = H5Dopen2(file, dataset, H5P_DEFAULT);
    ASSERT_GE(data, 0);
    const hid_t space = H5Dget_space(data);
    std::vector<double> values(size_t(H5Sget_simple_extent_npoints(space)));
    H5Sclose(space);
    ASSERT_GE(H5Dread(data, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0);
    values[values.size() / 2] += 1e-3;
    ASSERT_GE(H5Dwrite(data, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0);
    H5Dclose(data);
    H5Fclose(file);
    EXPECT_EQ(input_error([&] { read_checkpoint(path, key, state); }),
              path.string() + ": not a readable checkpoint: its state does not match the digest it was written "
                              "with (damaged on disk; delete it to resume from the one before)");
  }
}

// An input in the checkpoints' folder under a name the bake replaces and removes as its own is
// refused before the bake; an input under another name, and such a name that is no input, are not.
TEST(Checkpoint, AnInputNamedAsTheBakesOwnFilesIsRefused) {
  ScratchDir dir("input-named-as-a-journal");
  std::ofstream(dir.path / "frames-from-0.journal") << "0,3\n";
  std::ofstream(dir.path / "wind.csv") << "0,3\n";
  std::ofstream(dir.path / "checkpoint-5.h5") << "x";
  note_input_file(dir.path / "wind.csv");
  EXPECT_EQ(input_error([&] { check_checkpoint_folder(dir.path); }), "");
  note_input_file(dir.path / "frames-from-0.journal");
  EXPECT_EQ(input_error([&] { check_checkpoint_folder(dir.path); }),
            (dir.path / "frames-from-0.journal").string() +
                " is an input of this bake, in the checkpoints' folder under a name the bake replaces and removes as "
                "its own; expected another name for it, or another --checkpoint-dir");
  EXPECT_EQ(input_error([&] { check_checkpoint_folder(dir.path / "none"); }), "");
}

TEST(FrameJournal, KeepsWholeRecordsAndTruncatesToTheCheckpoint) {
  const ScratchDir scratch("journal");
  const fs::path& dir = scratch.path;
  const JournalLayout layout{"fnv1a64:0000000000000001", 10, 2, 1, true};
  FrameData frame;
  frame.positions = {1, 2, 3, 4, 5, 6};
  frame.velocities = {0.5f, 0, 0, 0, 0, -0.5f};
  frame.leaf_attached = {1};
  {
    FrameJournal journal = FrameJournal::create(dir / "j", layout);
    for (long long k = 10; k < 14; ++k) {
      frame.frame = k;
      frame.time = k / 24.0;
      frame.positions[0] = float(k);
      journal.append(frame);
    }
    journal.sync();
  }
  fs::resize_file(dir / "j", fs::file_size(dir / "j") - 3);  // a record cut short by a kill
  FrameJournal journal = FrameJournal::open(dir / "j", layout);
  EXPECT_EQ(journal.size(), 3);
  const FrameData second = journal.read(1);
  EXPECT_EQ(second.frame, 11);
  EXPECT_EQ(second.time, 11 / 24.0);
  EXPECT_EQ(second.positions[0], 11.0f);
  EXPECT_EQ(second.velocities, frame.velocities);
  journal.truncate(2);
  frame.frame = 12;
  journal.append(frame);
  EXPECT_EQ(journal.read(2).frame, 12);
  JournalLayout other = layout;
  other.first_frame = 0;
  EXPECT_NE(input_error([&] { FrameJournal::open(dir / "j", other); }).find("belongs to another bake"), std::string::npos);
}

}  // namespace
}  // namespace treeanim
