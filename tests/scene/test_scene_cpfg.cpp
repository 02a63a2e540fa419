// A scene naming a cpfg grammar and its view file (docs/scene.md "lsystem.view"): the files
// are found relative to the scene, the files they name beside them, and the scene's own keys
// override the view file's settings.
#include <unistd.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "common/errors.h"
#include "lsystem/lsystem.h"
#include "scene/scene.h"

namespace treeanim {
namespace {

namespace fs = std::filesystem;

// A vlab-like object folder: grammar, view file, and a function the view file names (y = 2x),
// used by its name.
fs::path write_object() {
  const fs::path dir = fs::temp_directory_path() / ("treeanim_test_scene_cpfg-" + std::to_string(::getpid())) / "object";
  fs::create_directories(dir);
  std::ofstream(dir / "plant.l") << "#define N 3\nLsystem: 1\nderivation length: N\nAxiom: #A(0)\n"
                                    "A(n) --> F(func(DOUBLE, n / N)) #[+ ~l(1)] A(n + 1)\nEndlsystem\n";
  std::ofstream(dir / "plant.v") << "angle increment: 90\ninitial line width: 0.5\nline width increment: 0.25\n"
                                    "surface: l leaf.s 1\nfunction: double.func\nviewpoint: 0,0,1\n";
  std::ofstream(dir / "double.func") << "fver 1 1\nname: DOUBLE\nrange: 0, 1\npoints: 2\n0 0\n1 2\n";
  return dir.parent_path();
}

Skeleton grow(const std::string& lsystem) {
  const fs::path base = write_object();
  struct RemovedAtTheEnd {  // also when growing throws
    fs::path path;
    ~RemovedAtTheEnd() {
      std::error_code ignored;
      fs::remove_all(path, ignored);
    }
  } folder{base};
  const Scene scene = load_scene_text(R"({"lsystem": )" + lsystem + "}", "s.json", base, {});
  return grow_skeleton(scene.lsystem, nullptr);
}

TEST(SceneCpfg, GrammarAndViewFileGrowTheTree) {
  const Skeleton k = grow(R"({"grammar": "object/plant.l", "view": "object/plant.v"})");
  ASSERT_EQ(k.segment_count(), 3u);
  // F(func(DOUBLE, n / 3)) with DOUBLE = 2x: lengths 0, 2/3, 4/3 along the heading, which never turns.
  EXPECT_NEAR(k.segment_end[2].y(), 2.0, 1e-3);
  // '#' adds the view's 0.25 to its initial 0.5, once before each F.
  EXPECT_EQ(k.segment_width, (std::vector<double>{0.75, 1.0, 1.25}));
  ASSERT_EQ(k.leaf_count(), 3u);
  // The leaf turned by the view's 90 degrees: heading -x.
  EXPECT_NEAR(k.leaf_heading[0].x(), -1.0, 1e-12);
}

TEST(SceneCpfg, SceneKeysOverrideTheViewFile) {
  const Skeleton k = grow(R"({"grammar": "object/plant.l", "view": "object/plant.v", "angle": 30})");
  EXPECT_NEAR(k.leaf_heading[0].x(), -std::sin(30 * std::numbers::pi / 180), 1e-12);
}

TEST(SceneCpfg, WithoutTheViewFileTheGrammarStopsAtFunc) {
  try {
    grow(R"({"grammar": "object/plant.l"})");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("plant.l:5:17: unknown name 'DOUBLE'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace treeanim
