// OutputSet: targets checked before simulating, nothing left behind on abort or failure,
// the GLB size limit refused early with the number of frames that would fit.
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "common/errors.h"
#include "formats/glb_size.h"
#include "formats_test_support.h"

namespace treeanim {
namespace {

using test::output;
using test::small_frame;
using test::small_info;
using test::small_model;

class OutputSetTest : public test::TempFolder {};

std::vector<OutputOptions> every_format() {
  std::vector<OutputOptions> outputs = {output("hdf5", "bake.h5"), output("obj", "obj/tree"),
                                        output("gltf", "gltf/tree"), output("glb", "anim.glb"),
                                        output("pc2", "tree.pc2")};
  for (size_t i = 0; i < outputs.size(); ++i) outputs[i].pointer = "/outputs/" + std::to_string(i);
  outputs[0].velocities = true;
  return outputs;
}

TEST_F(OutputSetTest, AbortMidBakeLeavesNoFile) {
  const TreeModel m = small_model();
  const BakeInfo info = small_info(5, 0);
  OutputSet set(every_format(), dir_, m, info);
  set.begin();
  set.push(small_frame(m, 0));
  set.push(small_frame(m, 1));
  set.abort();
  EXPECT_EQ(entries(), std::vector<std::string>{});  // the folders the checks made are gone too
}

TEST_F(OutputSetTest, DestructorWithoutFinishLeavesNoFile) {
  const TreeModel m = small_model();
  {
    OutputSet set(every_format(), dir_, m, small_info(5, 0));
    set.begin();
    set.push(small_frame(m, 0));
  }
  EXPECT_EQ(entries(), std::vector<std::string>{});
}

TEST_F(OutputSetTest, AbortKeepsFoldersThatStoodBefore) {
  const TreeModel m = small_model();
  std::filesystem::create_directories(dir_ / "obj");
  OutputSet set(every_format(), dir_, m, small_info(5, 0));
  set.begin();
  set.push(small_frame(m, 0));
  set.abort();
  EXPECT_EQ(entries(), std::vector<std::string>{"obj"});  // empty, yet not the bake's to remove
}

TEST_F(OutputSetTest, SecondSetOfTheSameOutputIsRefusedNamingTheHolder) {
  const TreeModel m = small_model();
  const std::vector<OutputOptions> outputs = {output("pc2", "tree.pc2")};
  // A lock is per process, so the holder is a child that locks the output and waits.
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  if (child == 0) {
    OutputSet held(outputs, dir_, m, small_info(5, 0));
    char byte = 1;
    if (::write(ready[1], &byte, 1) != 1) ::_exit(1);
    ::pause();
    ::_exit(0);
  }
  char byte = 0;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  try {
    OutputSet second(outputs, dir_, m, small_info(5, 0));
    ADD_FAILURE() << "a second writer of the same output was let in";
  } catch (const OutputError& e) {
    EXPECT_EQ(std::string(e.what()), (dir_ / "tree.pc2").string() + ": another bake is writing this output (process " +
                                         std::to_string(child) + ", lock " + (dir_ / ".tree.pc2.lock").string() +
                                         "); nothing was written: wait for it to end, or write elsewhere (-o)");
  }
  // Another format's file of the same name: an OBJ sequence's rest mesh is the point cache's.
  try {
    OutputSet other({output("obj", "tree")}, dir_, m, small_info(5, 0));
    ADD_FAILURE() << "a writer of the point cache's rest mesh was let in";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("lock " + (dir_ / ".tree.rest.obj.lock").string()), std::string::npos)
        << e.what();
  }
  ::kill(child, SIGKILL);  // the kernel drops its lock: the output is free again
  ::waitpid(child, nullptr, 0);
  OutputSet third(outputs, dir_, m, small_info(5, 0));
  third.abort();
  EXPECT_EQ(entries(), std::vector<std::string>{});  // the dead holder's lock file removed with ours
}

TEST_F(OutputSetTest, FinishRenamesEveryTemporary) {
  const TreeModel m = small_model();
  OutputSet set(every_format(), dir_, m, small_info(1, 0));
  EXPECT_TRUE(set.wants_velocities());
  set.begin();
  set.push(small_frame(m, 0));
  set.finish();
  EXPECT_EQ(entries(), (std::vector<std::string>{"anim.glb", "bake.h5", "gltf", "gltf/tree.0000.glb", "obj",
                                                 "obj/tree.0000.obj", "obj/tree.rest.mtl", "obj/tree.rest.obj",
                                                 "tree.pc2", "tree.rest.mtl", "tree.rest.obj"}));
  const auto paths = set.final_paths();
  ASSERT_EQ(paths.size(), 7u);
  EXPECT_EQ(paths[0].path, dir_ / "bake.h5");
  EXPECT_EQ(paths[1].path, dir_ / "obj/tree.rest.obj");
  EXPECT_EQ(paths[2].path, dir_ / "obj/tree.0000.obj");
  EXPECT_EQ(paths[3].path, dir_ / "gltf/tree.0000.glb");
  for (const SummaryFile& file : paths) EXPECT_EQ(file.files, 1);
}

// A sequence is named by its first and last frame's files and how many there are.
TEST_F(OutputSetTest, SummaryNamesASequenceByItsFirstAndLastFile) {
  const TreeModel m = small_model();
  std::vector<OutputOptions> outputs = every_format();
  for (OutputOptions& o : outputs) o.frame_step = 2;
  OutputSet set(outputs, dir_, m, small_info(5, 3));
  const auto paths = set.final_paths();
  ASSERT_EQ(paths.size(), 7u);
  EXPECT_EQ(paths[0].files, 1);
  EXPECT_EQ(paths[2].path, dir_ / "obj/tree.0003.obj");
  EXPECT_EQ(paths[2].last, dir_ / "obj/tree.0007.obj");
  EXPECT_EQ(paths[2].files, 3);
  EXPECT_EQ(paths[3].path, dir_ / "gltf/tree.0003.glb");
  EXPECT_EQ(paths[3].last, dir_ / "gltf/tree.0007.glb");
  EXPECT_EQ(paths[3].files, 3);
}

TEST_F(OutputSetTest, AFrameEveryWriterIsDoneWithComesBackToBeFilledAgain) {
  const TreeModel m = small_model();
  OutputSet set(every_format(), dir_, m, small_info(2, 0));
  set.begin();
  EXPECT_TRUE(set.spare_frame().positions.empty());  // none written yet
  const FrameData first = small_frame(m, 0);
  FrameData pushed = first;
  const float* const pushed_arrays[2] = {pushed.positions.data(), pushed.velocities.data()};
  set.push(std::move(pushed));
  set.push(small_frame(m, 1));
  set.finish();  // every writer done with both frames
  FrameData spare = set.spare_frame();
  // The arrays themselves come back (frame 1's, the last handed back), with their sizes.
  EXPECT_EQ(spare.frame, 1);
  EXPECT_EQ(spare.positions.size(), first.positions.size());
  EXPECT_EQ(spare.velocities.size(), first.velocities.size());
  FrameData older = set.spare_frame();
  EXPECT_EQ(older.frame, 0);
  EXPECT_EQ(older.positions.data(), pushed_arrays[0]);
  EXPECT_EQ(older.velocities.data(), pushed_arrays[1]);
  EXPECT_TRUE(set.spare_frame().positions.empty());  // each comes back once
}

// The message of the error that refuses `outputs`, "input: " before a bad-input one.
std::string output_error(const std::vector<OutputOptions>& outputs, const std::filesystem::path& dir,
                         const TreeModel& m, const BakeInfo& info) {
  try {
    OutputSet set(outputs, dir, m, info);
  } catch (const InputError& e) {
    return std::string("input: ") + e.what();
  } catch (const OutputError& e) {
    return e.what();
  }
  return "no error";
}

TEST_F(OutputSetTest, BadPathsAreFoundBeforeSimulating) {
  const TreeModel m = small_model();
  const BakeInfo info = small_info();
  test::bake({output("hdf5", "file")}, dir_, m, info);  // a file where a folder is wanted
  const std::string in_file = output_error({output("obj", "file/obj/tree")}, dir_, m, info);
  EXPECT_EQ(in_file.rfind((dir_ / "file/obj/tree.rest.obj").string() + ": cannot create the folder " +
                              (dir_ / "file/obj").string(), 0), 0u) << in_file;
  std::filesystem::create_directories(dir_ / "in_the_way.h5");
  EXPECT_EQ(output_error({output("hdf5", "in_the_way.h5")}, dir_, m, info),
            "input: /outputs/0/path: " + (dir_ / "in_the_way.h5").string() + " is a directory, left untouched; an "
            "output path must name a regular file or a new one");
  std::filesystem::create_directories(dir_ / "seq/tree.0003.obj");
  EXPECT_EQ(output_error({output("obj", "seq/tree")}, dir_, m, info),
            "input: /outputs/0/path: " + (dir_ / "seq/tree.0003.obj").string() + " is a directory, left untouched; "
            "an output path must name a regular file or a new one");
  // Not writable even for root: /proc takes no new files.
  const std::string unwritable = output_error({output("hdf5", "/proc/bake.h5")}, dir_, m, info);
  EXPECT_EQ(unwritable.rfind("/proc/bake.h5: cannot create a file in /proc: ", 0), 0u) << unwritable;
}

// What stands at a path, as lstat() sees it: type and device number, to tell "left as it was".
std::pair<mode_t, dev_t> node_at(const std::filesystem::path& path) {
  struct stat info {};
  if (::lstat(path.c_str(), &info) != 0) return {0, 0};
  return {info.st_mode, info.st_rdev};
}

// Every target of every format, with a device node (root only), a FIFO, a socket or a directory
// standing at it: refused before anything is written, and the node left as it was. The check
// looks with lstat(), so the FIFO is never opened (that would block).
TEST_F(OutputSetTest, TargetsThatAreNotRegularFilesAreRefusedAndLeftAlone) {
  const TreeModel m = small_model();
  const BakeInfo info = small_info(3, 0);
  const std::vector<std::pair<std::string, std::string>> targets = {
      {"hdf5", "bake.h5"},           {"glb", "anim.glb"},           {"pc2", "tree.pc2"},
      {"pc2", "tree.rest.obj"},      {"obj", "obj/tree.0001.obj"},  {"obj", "obj/tree.rest.obj"},
      {"gltf", "gltf/tree.0002.glb"}, {"mdd", "tree.mdd"},            {"vat", "vat/tree.normals.exr"},
      {"vat", "vat/tree.json"}};
  const std::vector<std::pair<std::string, std::string>> paths = {
      {"hdf5", "bake.h5"},   {"glb", "anim.glb"}, {"pc2", "tree.pc2"}, {"obj", "obj/tree"},
      {"gltf", "gltf/tree"}, {"mdd", "tree.mdd"}, {"vat", "vat/tree"}};
  for (const auto& [format, file] : targets) {
    for (const std::string kind : {"character device", "FIFO", "socket", "directory"}) {
      SCOPED_TRACE(format + " " + file + " " + kind);
      std::filesystem::remove_all(dir_);
      const std::filesystem::path at = dir_ / file;
      std::filesystem::create_directories(at.parent_path());
      int made = 0;
      if (kind == "character device") {
        if (::geteuid() != 0) continue;  // mknod needs root; CI runs as root
        made = ::mknod(at.c_str(), S_IFCHR | 0600, makedev(1, 3));  // what /dev/null is
      } else if (kind == "FIFO") {
        made = ::mkfifo(at.c_str(), 0600);
      } else if (kind == "socket") {
        made = test::bind_unix_socket(at);
      } else {
        std::filesystem::create_directory(at);
      }
      ASSERT_EQ(made, 0) << std::strerror(errno);
      const auto before = node_at(at);
      const std::vector<std::string> entries_before = entries();
      std::string path;
      for (const auto& [f, p] : paths)
        if (f == format) path = p;
      EXPECT_EQ(output_error({output(format, path)}, dir_, m, info),
                "input: /outputs/0/path: " + at.string() + " is a " + kind +
                    ", left untouched; an output path must name a regular file or a new one");
      EXPECT_EQ(node_at(at), before);
      EXPECT_EQ(entries(), entries_before);  // no folder, no probe, no temporary
    }
  }
}

// A symbolic link at the target is followed, as cp and editors do: the file it names gets the
// bake and the link stays. A dangling link creates its file; a loop and a link to a FIFO are refused.
TEST_F(OutputSetTest, SymbolicLinksAreFollowedAndKept) {
  namespace fs = std::filesystem;
  const TreeModel m = small_model();
  fs::create_directories(dir_ / "store");
  { std::ofstream(dir_ / "store/old.h5") << "old"; }
  fs::create_symlink("store/old.h5", dir_ / "bake.h5");
  fs::create_symlink("store/new.pc2", dir_ / "tree.pc2");  // dangling
  test::bake({output("hdf5", "bake.h5"), output("pc2", "tree.pc2")}, dir_, m, small_info(2, 0));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir_ / "bake.h5")));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir_ / "tree.pc2")));
  EXPECT_EQ(test::read_file(dir_ / "store/old.h5").substr(1, 3), "HDF");
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(dir_ / "store/new.pc2")));
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(dir_ / "tree.rest.obj")));  // named after the link

  fs::create_symlink("loop-b.h5", dir_ / "loop-a.h5");
  fs::create_symlink("loop-a.h5", dir_ / "loop-b.h5");
  EXPECT_EQ(output_error({output("hdf5", "loop-a.h5")}, dir_, m, small_info()),
            "input: /outputs/0/path: " + (dir_ / "loop-a.h5").string() +
                ": a loop of symbolic links, or a chain of more than 40");
  ASSERT_EQ(::mkfifo((dir_ / "store/pipe").c_str(), 0600), 0);
  fs::create_symlink("store/pipe", dir_ / "piped.glb");
  EXPECT_EQ(output_error({output("glb", "piped.glb")}, dir_, m, small_info()),
            "input: /outputs/0/path: " + (dir_ / "piped.glb").string() + " links to " +
                (dir_ / "store/pipe").string() + ", a FIFO, left untouched; an output path must name a regular "
                "file or a new one");
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(dir_ / "store/pipe")));
}

// Two outputs that reach one file, one of them through a link, are refused like two equal paths.
TEST_F(OutputSetTest, TwoOutputsCannotWriteOneFileThroughALink) {
  const TreeModel m = small_model();
  std::filesystem::create_symlink("a.h5", dir_ / "b.h5");
  std::vector<OutputOptions> outputs{output("hdf5", "a.h5"), output("hdf5", "b.h5")};
  outputs[1].pointer = "/outputs/1";
  EXPECT_EQ(output_error(outputs, dir_, m, small_info()),
            "input: /outputs/1/path: writes " + (dir_ / "a.h5").string() + ", which /outputs/0 writes too");
}

TEST_F(OutputSetTest, TwoOutputsCannotWriteOneFile) {
  const TreeModel m = small_model();
  std::vector<OutputOptions> outputs{output("obj", "tree"), output("pc2", "tree.pc2")};
  outputs[1].pointer = "/outputs/1";
  try {
    OutputSet set(outputs, dir_, m, small_info());
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "/outputs/1/path: writes " + (dir_ / "tree.rest.obj").string() +
                                         ", which /outputs/0 writes too");
  }
}

// A forest's look before its first tree: OutputSet's first check without a sink or a model, the
// same refusals as the set's, and nothing made (the set makes the folders obj/ and gltf/).
TEST_F(OutputSetTest, TargetsAreLookedAtWithoutCreatingAnything) {
  const TreeModel m = small_model();
  const BakeInfo info = small_info();
  const auto refusal = [&](const std::vector<OutputOptions>& outputs) -> std::string {
    try {
      OutputTargets targets;
      targets.add_outputs(outputs, dir_, info.frame_start, info.frame_count);
    } catch (const InputError& e) {
      return std::string("input: ") + e.what();
    }
    return "no error";
  };
  EXPECT_EQ(refusal(every_format()), "no error");
  EXPECT_EQ(entries(), std::vector<std::string>{});
  std::vector<OutputOptions> twice{output("obj", "tree"), output("pc2", "tree.pc2")};
  twice[1].pointer = "/outputs/1";
  EXPECT_EQ(refusal(twice), output_error(twice, dir_, m, info));
  std::filesystem::create_directories(dir_ / "seq/tree.0003.obj");
  const std::vector<OutputOptions> sequence{output("obj", "seq/tree")};
  EXPECT_EQ(refusal(sequence), output_error(sequence, dir_, m, info));
  EXPECT_NE(refusal(sequence), "no error");
}

// A folder a bake made and gives up is removed only while it is an empty folder: a file or a
// link that took its place meanwhile is someone else's.
TEST_F(OutputSetTest, UndoRemovesOnlyTheEmptyFoldersItMade) {
  MadeFolders made;
  std::error_code error;
  made.make(dir_ / "a/b/c", error);
  ASSERT_FALSE(error);
  made.make(dir_ / "x", error);
  std::filesystem::remove(dir_ / "a/b/c");
  std::ofstream(dir_ / "a/b/c") << "precious";  // a user's file where the folder was
  std::filesystem::remove(dir_ / "x");
  std::filesystem::create_directory_symlink(dir_ / "a", dir_ / "x");
  made.undo();
  EXPECT_TRUE(std::filesystem::is_regular_file(dir_ / "a/b/c"));
  EXPECT_TRUE(std::filesystem::is_symlink(dir_ / "x"));
  made.make(dir_ / "d/e", error);
  made.undo();
  EXPECT_FALSE(std::filesystem::exists(dir_ / "d"));
}

// Writers of a forest: one tree's file is no other tree's, nor the manifest's; a tree that is
// not written here keeps its files but is not looked at; a folder that takes no file is found
// by the probe, and the folders it made are removed by their undo.
TEST_F(OutputSetTest, EachFileOfSeveralWritersHasOne) {
  const BakeInfo info = small_info();
  const auto refusal = [&](const auto& add) -> std::string {
    MadeFolders made;
    try {
      OutputTargets targets;
      targets.add_file(dir_ / "forest.json", "the forest's manifest");
      add(targets);
      targets.probe(made);
    } catch (const std::exception& e) {
      made.undo();
      return e.what();
    }
    made.undo();
    return "no error";
  };
  const std::vector<OutputOptions> a{output("hdf5", "a.h5"), output("pc2", "shared")};
  EXPECT_EQ(refusal([&](OutputTargets& t) { t.add_outputs(a, dir_, info.frame_start, info.frame_count, "tree a"); }),
            "no error");
  EXPECT_EQ(refusal([&](OutputTargets& t) {
              t.add_outputs(a, dir_, info.frame_start, info.frame_count, "tree a", false);
              t.add_outputs({output("hdf5", "shared.pc2")}, dir_, info.frame_start, info.frame_count, "tree b");
            }),
            "/outputs/0/path of tree b: writes " + (dir_ / "shared.pc2").string() +
                ", which /outputs/0 of tree a writes too");
  EXPECT_EQ(refusal([&](OutputTargets& t) {
              t.add_outputs({output("hdf5", "forest.json")}, dir_, info.frame_start, info.frame_count, "tree forest");
            }),
            "/outputs/0/path of tree forest: writes " + (dir_ / "forest.json").string() +
                ", which the forest's manifest writes too");
  std::filesystem::create_directories(dir_ / "b.h5");
  EXPECT_EQ(refusal([&](OutputTargets& t) {
              t.add_outputs({output("hdf5", "b.h5")}, dir_, info.frame_start, info.frame_count, "tree b", false);
            }),
            "no error");
  std::filesystem::remove(dir_ / "b.h5");
  std::ofstream(dir_ / "blocked") << "a file where a folder goes";
  EXPECT_EQ(refusal([&](OutputTargets& t) {
              t.add_outputs({output("hdf5", "deep/er/c.h5"), output("hdf5", "blocked/c.h5")}, dir_, info.frame_start,
                            info.frame_count, "tree c");
            }),
            (dir_ / "blocked/c.h5").string() + ": cannot create the folder " + (dir_ / "blocked").string() +
                ": Not a directory");
  EXPECT_EQ(entries(), std::vector<std::string>{"blocked"});
  // A dangling link where a folder goes is someone's: refused, and left where it was.
  std::filesystem::remove(dir_ / "blocked");
  std::filesystem::create_directory_symlink(dir_ / "nowhere", dir_ / "linked");
  EXPECT_NE(refusal([&](OutputTargets& t) {
              t.add_outputs({output("hdf5", "linked/c.h5")}, dir_, info.frame_start, info.frame_count, "tree c");
            }),
            "no error");
  EXPECT_TRUE(std::filesystem::is_symlink(dir_ / "linked"));
}

TEST_F(OutputSetTest, FailedRenameRemovesEveryTemporary) {
  const TreeModel m = small_model();
  const BakeInfo info = small_info(2, 0);
  OutputSet set({output("hdf5", "a.h5"), output("obj", "b")}, dir_, m, info);
  set.begin();
  set.push(small_frame(m, 0));
  set.push(small_frame(m, 1));
  std::filesystem::create_directories(dir_ / "b.0001.obj/occupied");  // appears during the bake
  try {
    set.finish();
    FAIL() << "finished";
  } catch (const OutputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind((dir_ / "b.0001.obj").string() + ": a directory appeared at the output "
                                          "path during the bake", 0), 0u) << e.what();
  }
  // a.h5 and b.rest.obj, b.0000.obj were renamed before the failure: whole files. No temporary stays.
  for (const std::string& name : entries()) EXPECT_EQ(name.find(".tmp-"), std::string::npos) << name;
}

TEST_F(OutputSetTest, WriterFailureSurfacesInPush) {
  const TreeModel m = small_model();
  OutputSet set({output("obj", "seq/tree")}, dir_, m, small_info(50, 0));
  set.begin();
  std::filesystem::remove_all(dir_ / "seq");  // the writer thread can no longer create files
  try {
    for (long long f = 0; f < 50; ++f) set.push(small_frame(m, f));
    set.finish();
    FAIL() << "no error";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find((dir_ / "seq/tree.0000.obj").string() + ": cannot create"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(entries().empty());
}

TEST_F(OutputSetTest, GlbOverFourGibIsRefusedWithTheFramesThatFit) {
  TreeModel m = small_model();
  m.rest_positions = Eigen::Matrix3Xd::Zero(3, 100000);  // only the counts matter for the size
  m.triangles.clear();
  const BakeInfo info = small_info(4000, 0);
  const std::string error = output_error({output("glb", "anim.glb")}, dir_, m, info);
  char size[32];
  std::snprintf(size, sizeof size, "%.2f GiB", double(animated_glb_bytes(m, info, 1)) / double(1ull << 30));
  const std::string expected = "input: /outputs/0: the animated GLB " + (dir_ / "anim.glb").string() + " would be " + size +
                               " (100000 vertices x 4000 frames), over glTF's 4 GiB GLB limit; at most ";
  ASSERT_EQ(error.rfind(expected, 0), 0u) << error;
  const long long fits = std::stoll(error.substr(expected.size()));
  BakeInfo shorter = info;
  shorter.frame_count = fits;
  EXPECT_LE(animated_glb_bytes(m, shorter, 1), kGlbMaxBytes);
  shorter.frame_count = fits + 1;
  EXPECT_GT(animated_glb_bytes(m, shorter, 1), kGlbMaxBytes);
  EXPECT_TRUE(entries().empty());
  // The largest bake a scene may ask for is refused as fast, without memory per frame.
  BakeInfo longest = info;
  longest.frame_count = 10000000;
  EXPECT_NE(output_error({output("glb", "anim.glb")}, dir_, m, longest).find("at most " + std::to_string(fits)),
            std::string::npos);
  OutputOptions stepped = output("glb", "anim.glb", 2);  // half the frames fit
  EXPECT_NO_THROW(OutputSet(std::vector<OutputOptions>{stepped}, dir_, m, info));
}

}  // namespace
}  // namespace treeanim
