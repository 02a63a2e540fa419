// Room on disk before a bake: needs summed by filesystem against its free space, the message
// naming the path, what is needed and what is free; a real filesystem measured by statvfs.
#include <gtest/gtest.h>

#include <map>

#include "common/errors.h"
#include "files/free_space.h"
#include "temp_folder_test.h"

namespace treeanim {
namespace {

class FreeSpaceTest : public TempFolderTest {
 protected:
  FreeSpaceTest() : TempFolderTest("treeanim_free_space") {}
};

// Two filesystems: "big" folders on device 1 with 1 TB free, the rest on device 2 with 4.5 MB.
FreeSpace two_filesystems(const std::filesystem::path& folder) {
  return folder.filename() == "big" ? FreeSpace{1, 1e12} : FreeSpace{2, 4.5e6};
}

std::string refusal(const std::vector<SpaceNeed>& needs) {
  try {
    check_free_space(needs, two_filesystems);
  } catch (const OutputError& e) {
    return e.what();
  }
  return "";
}

TEST_F(FreeSpaceTest, RefusesABakeLargerThanItsFilesystemsFreeSpace) {
  std::filesystem::create_directories(dir_ / "big");
  std::filesystem::create_directories(dir_ / "small");
  EXPECT_EQ(refusal({{dir_ / "small/bake.h5", 104e9}}),
            (dir_ / "small/bake.h5").string() + ": not enough free space: the bake needs 104 GB on its filesystem, "
                                               "4.5 MB free; make room, write elsewhere (-o), or skip this estimate "
                                               "with --no-space-check");
  EXPECT_EQ(refusal({{dir_ / "big/bake.h5", 104e9}, {dir_ / "small/tree.pc2", 4e6}}), "");
}

TEST_F(FreeSpaceTest, SumsTheNeedsOfOneFilesystem) {
  std::filesystem::create_directories(dir_ / "small");
  // 3 MB and 2 MB each fit in 4.5 MB; together they do not. A folder still to be made is
  // measured at its nearest existing ancestor (here `small`).
  const std::string message = refusal({{dir_ / "small/a.pc2", 3e6}, {dir_ / "small/seq/b/tree.0001.obj", 2e6}});
  EXPECT_NE(message.find((dir_ / "small/a.pc2").string() + ": not enough free space"), std::string::npos) << message;
  EXPECT_NE(message.find("needs 5 MB on its filesystem, 4.5 MB free"), std::string::npos) << message;
}

TEST_F(FreeSpaceTest, MeasuresARealFilesystem) {
  const FreeSpace space = filesystem_free_space(dir_);
  EXPECT_GT(space.bytes, 0);
  EXPECT_THROW(check_free_space({{dir_ / "bake.h5", space.bytes * 2 + 1e15}}), OutputError);
  EXPECT_NO_THROW(check_free_space({{dir_ / "bake.h5", 1}}));
}

TEST(BytesText, DecimalUnitsWithThreeDigits) {
  EXPECT_EQ(bytes_text(104e9), "104 GB");
  EXPECT_EQ(bytes_text(4.5e6), "4.5 MB");
  EXPECT_EQ(bytes_text(512), "512 B");
}

}  // namespace
}  // namespace treeanim
