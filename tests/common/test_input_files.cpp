// The inputs a process noted, known by identity: any name of a noted file leads to it while the
// noted name still does.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/input_files.h"
#include "temp_folder_test.h"

namespace treeanim {
namespace {

class InputFiles : public TempFolderTest {
 protected:
  InputFiles() : TempFolderTest("treeanim_inputs") {}
};

TEST_F(InputFiles, AnyLinkToANotedFileIsThatInput) {
  std::ofstream(dir_ / "grammar.l") << "Axiom: F\n";
  std::filesystem::create_symlink(dir_ / "grammar.l", dir_ / "link.l");
  std::filesystem::create_hard_link(dir_ / "grammar.l", dir_ / "hard.l");
  EXPECT_EQ(input_file_at(dir_ / "link.l"), "");
  note_input_file(dir_ / "grammar.l");
  EXPECT_EQ(input_file_at(dir_ / "link.l"), (dir_ / "grammar.l").string());
  EXPECT_EQ(input_file_at(dir_ / "hard.l"), (dir_ / "grammar.l").string());
  EXPECT_EQ(input_file_at(dir_ / "other.l"), "");  // nothing there
}

// An input removed after it was read can give its inode to a file made later (an output of the
// same process): that file is not the input. Moving the input away stands for it here, since
// whether a freed inode is given again is the file system's choice.
TEST_F(InputFiles, ANameThatNoLongerLeadsToTheFileIsNoInput) {
  std::ofstream(dir_ / "leaf.bin") << "1234";
  note_input_file(dir_ / "leaf.bin");
  std::filesystem::rename(dir_ / "leaf.bin", dir_ / "bake.h5");
  EXPECT_EQ(input_file_at(dir_ / "bake.h5"), "");
  note_input_file(dir_ / "bake.h5");  // noted again under its new name
  EXPECT_EQ(input_file_at(dir_ / "bake.h5"), (dir_ / "bake.h5").string());
}

}  // namespace
}  // namespace treeanim
