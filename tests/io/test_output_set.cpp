// OutputSet: targets checked before simulating, nothing left behind on abort or failure,
// the GLB size limit refused early with the number of frames that would fit.
#include <cstdio>

#include "common/errors.h"
#include "io/glb_size.h"
#include "io_test_support.h"

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
  EXPECT_EQ(entries(), (std::vector<std::string>{"gltf", "obj"}));  // folders made by the checks
}

TEST_F(OutputSetTest, DestructorWithoutFinishLeavesNoFile) {
  const TreeModel m = small_model();
  {
    OutputSet set(every_format(), dir_, m, small_info(5, 0));
    set.begin();
    set.push(small_frame(m, 0));
  }
  EXPECT_EQ(entries(), (std::vector<std::string>{"gltf", "obj"}));
}

TEST_F(OutputSetTest, FinishRenamesEveryTemporary) {
  const TreeModel m = small_model();
  OutputSet set(every_format(), dir_, m, small_info(1, 0));
  EXPECT_TRUE(set.wants_velocities());
  set.begin();
  set.push(small_frame(m, 0));
  set.finish();
  EXPECT_EQ(entries(), (std::vector<std::string>{"anim.glb", "bake.h5", "gltf", "gltf/tree.0000.glb", "obj",
                                                 "obj/tree.0000.obj", "obj/tree.rest.obj", "tree.pc2",
                                                 "tree.rest.obj"}));
  const auto paths = set.final_paths();
  ASSERT_EQ(paths.size(), 7u);
  EXPECT_EQ(paths[0], dir_ / "bake.h5");
  EXPECT_EQ(paths[1], dir_ / "obj/tree.rest.obj");
  EXPECT_EQ(paths[2], dir_ / "obj/tree.0000.obj");
  EXPECT_EQ(paths[3], dir_ / "gltf/tree.0000.glb");
}

std::string output_error(const std::vector<OutputOptions>& outputs, const std::filesystem::path& dir,
                         const TreeModel& m, const BakeInfo& info) {
  try {
    OutputSet set(outputs, dir, m, info);
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
            (dir_ / "in_the_way.h5").string() + ": a directory is in the way of the output file");
  std::filesystem::create_directories(dir_ / "seq/tree.0003.obj");
  EXPECT_EQ(output_error({output("obj", "seq/tree")}, dir_, m, info),
            (dir_ / "seq/tree.0003.obj").string() + ": a directory is in the way of the output file");
  // Not writable even for root: /proc takes no new files.
  const std::string unwritable = output_error({output("hdf5", "/proc/bake.h5")}, dir_, m, info);
  EXPECT_EQ(unwritable.rfind("/proc/bake.h5: cannot create a file in /proc: ", 0), 0u) << unwritable;
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
    EXPECT_EQ(std::string(e.what()).rfind((dir_ / "b.0001.obj").string() + ": cannot rename", 0), 0u) << e.what();
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
  const std::string expected = (dir_ / "anim.glb").string() + ": the animated GLB would be " + size +
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
