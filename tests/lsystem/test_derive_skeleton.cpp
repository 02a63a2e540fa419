// grow_skeleton: grammar (file or inline) => derivation => homomorphism => turtle, with the
// scene's overrides.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/errors.h"
#include "lsystem/lsystem.h"
#include "input_error_of.h"

namespace treeanim {
namespace {

std::filesystem::path grammar_file(const std::string& name) {
  return std::filesystem::path(TREEANIM_SOURCE_DIR) / "grammars" / name;
}

std::string derive_error_of(const LsystemOptions& options) {
  GrowthStats stats;
  return input_error_of([&] { grow_skeleton(options, &stats); });
}

TEST(GrowSkeleton, InlineGrammarWithHomomorphismAndDefines) {
  LsystemOptions options;
  options.axiom = "A(1)";
  options.productions = {"A(x) --> A(x*k)", "homomorphism", "A(x) --> F(x)"};
  options.defines = {{"k", 2}};
  options.iterations = 3;
  GrowthStats stats;
  const Skeleton skeleton = grow_skeleton(options, &stats);
  EXPECT_EQ(stats.modules, 1u);  // the derived word is A(8); F(8) exists only for the turtle
  EXPECT_EQ(stats.iterations, 3);
  ASSERT_EQ(skeleton.segment_count(), 1u);
  EXPECT_NEAR((skeleton.segment_end[0] - Eigen::Vector3d(0, 8, 0)).norm(), 0.0, 1e-12);
}

TEST(GrowSkeleton, SceneAngleAndStepOverrideTheGrammar) {
  LsystemOptions options;
  options.axiom = "+F";
  options.productions = {"angle: 30"};
  options.iterations = 0;
  options.step = 2.0;
  options.angle = 90.0;
  GrowthStats stats;
  const Skeleton skeleton = grow_skeleton(options, &stats);
  ASSERT_EQ(skeleton.segment_count(), 1u);
  EXPECT_NEAR((skeleton.segment_end[0] - Eigen::Vector3d(-2, 0, 0)).norm(), 0.0, 1e-12);  // '+' turns H toward L = (-1, 0, 0)
}

TEST(GrowSkeleton, SegmentCountOfAbop124aPerStep) {
  // Fig. 1.24a draws every F: 5^n segments after n steps.
  LsystemOptions options;
  options.grammar = grammar_file("abop-1.24a.lsys");
  size_t five = 1;
  for (int n = 0; n <= 5; ++n, five *= 5) {
    options.iterations = n;
    GrowthStats stats;
    EXPECT_EQ(grow_skeleton(options, &stats).segment_count(), five) << n;
  }
}

TEST(GrowSkeleton, ShippedGrammarsGrow) {
  for (const auto& entry : std::filesystem::directory_iterator(grammar_file(""))) {
    if (entry.path().extension() != ".lsys") continue;
    SCOPED_TRACE(entry.path().string());
    LsystemOptions options;
    options.grammar = entry.path();
    GrowthStats stats;
    const Skeleton skeleton = grow_skeleton(options, &stats);
    EXPECT_GT(stats.modules, 0u);
    EXPECT_GT(skeleton.segment_count(), 0u);
  }
}

TEST(GrowSkeleton, SceneDefineMustExistInTheFile) {
  LsystemOptions options;
  options.grammar = grammar_file("abop-2.6a-monopodial.lsys");
  options.defines = {{"r9", 0.5}};
  options.scene_name = "scene.json";
  EXPECT_EQ(derive_error_of(options), "scene.json: /lsystem/defines/r9: the grammar " + options.grammar->string() +
                                          " has no '#define r9' (it defines: r1, r2, a0, a2, d, wr)");
}

TEST(GrowSkeleton, SceneDefineCannotReplaceAMacroWithArguments) {
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "treeanim-macro-define.lsys";
  std::ofstream(file) << "#define M(x) x*2\nderivation length: 0\naxiom: F(M(3))\n";
  LsystemOptions options;
  options.grammar = file;
  options.defines = {{"M", 7}};
  options.scene_name = "scene.json";
  EXPECT_EQ(derive_error_of(options), "scene.json: /lsystem/defines/M: the grammar " + file.string() +
                                          " defines 'M' as a macro with arguments ('#define M(...)'), which no "
                                          "number replaces: only a constant #define takes the scene's value");
  std::filesystem::remove(file);
}

TEST(GrowSkeleton, InlineGrammarNeedsIterations) {
  LsystemOptions options;
  options.axiom = std::string("F");  // (a plain = "F" trips g++ 12's false -Wrestrict)
  options.productions = {"F --> FF"};
  EXPECT_EQ(derive_error_of(options),
            "/lsystem/axiom: the grammar has no 'derivation length:'; give the number of steps as "
            "/lsystem/iterations");
}

TEST(GrowSkeleton, MissingFile) {
  LsystemOptions options;
  options.grammar = "/nonexistent/tree.lsys";
  EXPECT_EQ(derive_error_of(options), "/nonexistent/tree.lsys: cannot read the grammar file (no such file)");
}

TEST(GrowSkeleton, InlineErrorsNameTheRule) {
  LsystemOptions options;
  options.axiom = "A(1)";
  options.productions = {"A(x) --> A(x)", "A(x) --> B(x, q)"};
  options.iterations = 1;
  EXPECT_EQ(derive_error_of(options),
            "/lsystem/productions/1, column 15: unknown name 'q' (expected a formal parameter (x))");
}

}  // namespace
}  // namespace treeanim
