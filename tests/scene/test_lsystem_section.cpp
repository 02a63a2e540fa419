// read_lsystem_options: the /lsystem section, its defaults and its JSON-pointer messages.
#include <gtest/gtest.h>

#include "common/errors.h"
#include "scene/lsystem_section.h"
#include "input_error_of.h"

namespace treeanim {
namespace {

LsystemOptions read(Json& scene) {
  SceneReader reader(scene, "/scenes", "scene.json");
  LsystemOptions options = read_lsystem_options(reader.root().object("lsystem"), 77);
  reader.check_unknown_keys();
  return options;
}

std::string lsystem_error_of(const char* text) {
  Json scene = Json::parse(text);
  return input_error_of([&] { read(scene); });
}

TEST(LsystemOptions, FileGrammarWithDefaultsFilledIn) {
  Json scene = Json::parse(R"({"lsystem": {"grammar": "../grammars/tree.lsys", "defines": {"r1": 0.8}}})");
  const LsystemOptions o = read(scene);
  EXPECT_EQ(*o.grammar, std::filesystem::path("/grammars/tree.lsys"));
  EXPECT_EQ(o.defines, (std::vector<std::pair<std::string, double>>{{"r1", 0.8}}));
  // null takes the default, the grammar's own value: no define is replaced.
  Json unset = Json::parse(R"({"lsystem": {"grammar": "../grammars/tree.lsys", "defines": {"r1": null}}})");
  EXPECT_TRUE(read(unset).defines.empty());
  EXPECT_FALSE(o.iterations);
  EXPECT_EQ(o.seed, 77u);  // the scene's top-level seed
  EXPECT_EQ(o.step, 1.0);
  EXPECT_EQ(o.max_modules, 20'000'000u);
  EXPECT_EQ(o.inline_name(), "scene.json: /lsystem");
  EXPECT_EQ(scene["lsystem"]["seed"], 77);
  EXPECT_EQ(scene["lsystem"]["max_modules"], 20'000'000);
}

// A tropism is a direction: any length, however small, once it is not zero.
TEST(LsystemOptions, TropismOfAnyLength) {
  Json tiny = Json::parse(R"json({"lsystem": {"grammar": "tree.lsys", "tropism": [1e-300, 0, 0]}})json");
  EXPECT_EQ(*read(tiny).tropism, Eigen::Vector3d(1e-300, 0, 0));
  EXPECT_NE(lsystem_error_of(R"json({"lsystem": {"grammar": "tree.lsys", "tropism": [0, 0, 0]}})json")
                .find("/lsystem/tropism: expected a non-zero direction"),
            std::string::npos);
}

TEST(LsystemOptions, InlineGrammar) {
  Json scene = Json::parse(R"json({"lsystem": {"axiom": "A(1)", "productions": ["A(x) --> F(x)A(x*k)"],
      "defines": {"k": 2}, "iterations": 4, "seed": 5, "step": 0.1, "angle": 30, "max_modules": 1000,
      "width_factor": 0.5, "tropism": [0, -1, 0], "tropism_elasticity": 0.2}})json");
  const LsystemOptions o = read(scene);
  EXPECT_FALSE(o.grammar);
  EXPECT_EQ(o.axiom, "A(1)");
  EXPECT_EQ(o.productions, (std::vector<std::string>{"A(x) --> F(x)A(x*k)"}));
  EXPECT_EQ(o.iterations, 4);
  EXPECT_EQ(o.seed, 5u);
  EXPECT_EQ(o.step, 0.1);
  EXPECT_EQ(o.angle, 30.0);
  EXPECT_EQ(o.max_modules, 1000u);
  EXPECT_EQ(o.width_factor, 0.5);
  EXPECT_EQ(*o.tropism, Eigen::Vector3d(0, -1, 0));
  EXPECT_EQ(o.tropism_elasticity, 0.2);
}

TEST(LsystemOptions, ErrorsAreJsonPointers) {
  EXPECT_EQ(lsystem_error_of(R"({"lsystem": {}})"),
            "scene.json: /lsystem/grammar: expected a grammar file, or an inline grammar as /lsystem/axiom and "
            "/lsystem/productions (or a /species, which brings its own)");
  EXPECT_EQ(lsystem_error_of(R"({"lsystem": {"grammar": "a.lsys", "axiom": "F"}})"),
            "scene.json: /lsystem/axiom: give either a grammar file (/lsystem/grammar) or an inline grammar "
            "(/lsystem/axiom), not both");
  EXPECT_EQ(lsystem_error_of(R"({"lsystem": {"grammar": "a.lsys", "productions": ["F --> FF"]}})"),
            "scene.json: /lsystem/productions: inline productions go with /lsystem/axiom, not with a grammar "
            "file (/lsystem/grammar)");
  EXPECT_EQ(lsystem_error_of(R"({"lsystem": {"axiom": "F", "productions": ["F --> FF", 3]}})"),
            "scene.json: /lsystem/productions/1: expected a string (one production), got 3");
  EXPECT_EQ(lsystem_error_of(R"({"lsystem": {"axiom": "F", "productions": "F --> FF"}})"),
            "scene.json: /lsystem/productions: expected an array of strings (one production each), got "
            "\"F --> FF\"");
  EXPECT_EQ(lsystem_error_of(R"({"lsystem": {"axiom": "F", "defines": {"k": "x"}}})"),
            "scene.json: /lsystem/defines/k: expected a finite number, got \"x\"");
  EXPECT_EQ(lsystem_error_of(R"({"lsystem": {"axiom": "F", "defines": {"2k": 1}}})"),
            "scene.json: /lsystem/defines/2k: expected a name of letters, digits and '_' (not starting with a digit)");
  EXPECT_EQ(lsystem_error_of(R"({"lsystem": {"axiom": "F", "iterations": -1}})"),
            "scene.json: /lsystem/iterations: expected an integer in [0, 100000], got -1");
  EXPECT_EQ(lsystem_error_of(R"({"lsystem": {"axiom": "F", "step": 0}})"),
            "scene.json: /lsystem/step: expected a number > 0, got 0");
  EXPECT_EQ(lsystem_error_of(R"({"lsystem": {"axiom": "F", "tropism": [0, 0, 0]}})"),
            "scene.json: /lsystem/tropism: expected a non-zero direction [x, y, z] at most 1e6 long, got [0,0,0]");
  EXPECT_EQ(lsystem_error_of(R"({"lsystem": {"axiom": "F", "iteration": 3}})"),
            "scene.json: /lsystem/iteration: unknown key (did you mean /lsystem/iterations?)");
}

}  // namespace
}  // namespace treeanim
