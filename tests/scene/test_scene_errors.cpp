// Malformed scenes: each must give exit-2 InputError with the exact pointer and message.
#include <gtest/gtest.h>

#include "common/errors.h"
#include "scene/scene.h"

namespace treeanim {
namespace {

// A minimal valid scene: inline grammar, no outputs.
const char* kValid = R"({"lsystem": {"axiom": "F", "iterations": 0}})";

std::string scene_error_of(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    load_scene_text(text, "s.json", "/scenes", overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SceneErrors, ValidSceneLoads) { EXPECT_EQ(scene_error_of(kValid), ""); }

TEST(SceneErrors, SyntaxErrorGivesLineAndColumn) {
  const std::string message = scene_error_of("{\n  \"time\": {\"fps\": 24,}\n}");
  EXPECT_EQ(message.rfind("s.json:2:22: JSON syntax error: ", 0), 0u) << message;
}

TEST(SceneErrors, UnterminatedStringGivesLineAndColumn) {
  const std::string message = scene_error_of("{\"lsystem\": {\"axiom\": \"F}}\n");
  EXPECT_EQ(message.rfind("s.json:1:", 0), 0u) << message;
  EXPECT_NE(message.find("JSON syntax error"), std::string::npos) << message;
}

TEST(SceneErrors, EmptyFileIsASyntaxError) {
  EXPECT_EQ(scene_error_of("").rfind("s.json:1:1: JSON syntax error: ", 0), 0u) << scene_error_of("");
}

TEST(SceneErrors, TopLevelMustBeAnObject) {
  EXPECT_EQ(scene_error_of("[1, 2]"), "s.json: /: expected a JSON object at the top level, got [1,2]");
}

TEST(SceneErrors, UnknownTopLevelKey) {
  EXPECT_EQ(scene_error_of(R"({"lsystem": {"axiom": "F"}, "tme": {}})"),
            "s.json: /tme: unknown key (did you mean /time?)");
}

TEST(SceneErrors, UnknownTimeKey) {
  EXPECT_EQ(scene_error_of(R"({"lsystem": {"axiom": "F"}, "time": {"fsp": 30}})"),
            "s.json: /time/fsp: unknown key (did you mean /time/fps?)");
}

TEST(SceneErrors, FpsWrongType) {
  EXPECT_EQ(scene_error_of(R"({"lsystem": {"axiom": "F"}, "time": {"fps": "fast"}})"),
            "s.json: /time/fps: expected a number in [1, 1000], got \"fast\"");
}

TEST(SceneErrors, FpsZero) {
  EXPECT_EQ(scene_error_of(R"({"lsystem": {"axiom": "F"}, "time": {"fps": 0}})"),
            "s.json: /time/fps: expected a number in [1, 1000], got 0");
}

TEST(SceneErrors, FramesZero) {
  EXPECT_EQ(scene_error_of(R"({"lsystem": {"axiom": "F"}, "time": {"frames": 0}})"),
            "s.json: /time/frames: expected an integer in [1, 10000000], got 0");
}

TEST(SceneErrors, FramesFractional) {
  EXPECT_EQ(scene_error_of(R"({"lsystem": {"axiom": "F"}, "time": {"frames": 2.5}})"),
            "s.json: /time/frames: expected an integer in [1, 10000000], got 2.5");
}

TEST(SceneErrors, SubstepsNegative) {
  EXPECT_EQ(scene_error_of(R"({"lsystem": {"axiom": "F"}, "time": {"substeps": -1}})"),
            "s.json: /time/substeps: expected an integer in [1, 10000], got -1");
}

TEST(SceneErrors, SeedNegative) {
  EXPECT_EQ(scene_error_of(R"({"lsystem": {"axiom": "F"}, "seed": -3})"),
            "s.json: /seed: expected an integer in [0, 9007199254740992], got -3");
}

TEST(SceneErrors, OutputsMustBeAnArray) {
  EXPECT_EQ(scene_error_of(R"({"lsystem": {"axiom": "F"}, "outputs": {"format": "hdf5"}})"),
            "s.json: /outputs: expected an array of objects, got {\"format\":\"hdf5\"}");
}

TEST(SceneErrors, OutputElementMustBeAnObject) {
  EXPECT_EQ(scene_error_of(R"({"lsystem": {"axiom": "F"}, "outputs": ["bake.h5"]})"),
            "s.json: /outputs/0: expected an object, got \"bake.h5\"");
}

TEST(SceneErrors, DescriptionMustBeAString) {
  EXPECT_EQ(scene_error_of(R"({"lsystem": {"axiom": "F"}, "description": 5})"),
            "s.json: /description: expected a string, got 5");
}

TEST(SceneErrors, SectionMustBeAnObject) {
  EXPECT_EQ(scene_error_of(R"({"lsystem": {"axiom": "F"}, "time": [24]})"),
            "s.json: /time: expected an object, got [24]");
}

TEST(SceneErrors, OverrideIntroducesUnknownKey) {
  EXPECT_EQ(scene_error_of(kValid, {"time.fsp=30"}),
            "--set 'time.fsp=30': /time/fsp: unknown key (did you mean /time/fps?)");
}

TEST(SceneErrors, OverrideWithoutEquals) {
  EXPECT_EQ(scene_error_of(kValid, {"time.fps"}), "--set 'time.fps': expected PATH=VALUE, e.g. lsystem.iterations=6");
}

TEST(SceneErrors, OverrideValueIsValidated) {
  EXPECT_EQ(scene_error_of(kValid, {"time.fps=-1"}),
            "--set 'time.fps=-1': /time/fps: expected a number in [1, 1000], got -1");
  // Below an override's path the value is the override's; beside it, the file's.
  EXPECT_EQ(scene_error_of(kValid, {"wind={\"keys\": [{\"time\": 0, \"speed\": -3}]}"}),
            "--set 'wind={\"keys\": [{\"time\": 0, \"speed\": -3}]}': /wind/keys/0/speed: expected a number in "
            "[0, 113], got -3");
  EXPECT_EQ(scene_error_of(R"({"lsystem": {"axiom": "F"}, "time": {"frames": -1}})", {"time.fps=30"}),
            "s.json: /time/frames: expected an integer in [1, 10000000], got -1");
}

TEST(SceneErrors, OverrideOfOnePathTwice) {
  EXPECT_EQ(scene_error_of(kValid, {"time.fps=30", "time.frames=4", "time.fps=24"}),
            "--set 'time.fps=24': /time/fps is set already by --set 'time.fps=30': expected each path once, and "
            "a whole value before its parts");
  // The whole after a part would drop the part; a part after the whole changes it.
  EXPECT_EQ(scene_error_of(kValid, {"time.fps=30", "time={\"frames\": 5}"}),
            "--set 'time={\"frames\": 5}': /time holds /time/fps, set already by --set 'time.fps=30': expected each "
            "path once, and a whole value before its parts");
  EXPECT_EQ(load_scene_text(kValid, "s.json", ".", {"time={\"frames\": 5}", "time.fps=30"}).time.fps, 30);
}

TEST(SceneErrors, OverrideIndexStartsAnArray) {
  const Scene scene = load_scene_text(kValid, "s.json", ".", {"outputs.0.format=hdf5", "outputs.0.path=a.h5"});
  ASSERT_EQ(scene.outputs.size(), 1u);
  EXPECT_STREQ(scene.outputs[0].format->name, "hdf5");
}

TEST(SceneErrors, MissingFileNamesTheResolvedPath) {
  try {
    load_scene("/nonexistent/dir/scene.json", {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/dir/scene.json: cannot read the scene file (no such file)");
  }
}

TEST(SceneOverrides, ParsesJsonValuesAndFallsBackToStrings) {
  Json document = Json::parse(R"({"lsystem": {"iterations": 3}})");
  apply_override(document, "lsystem.iterations=6");
  apply_override(document, "lsystem.grammar=trees/oak.lsys");
  apply_override(document, "wind.keys=[{\"time\": 0, \"speed\": 3}]");
  apply_override(document, "hsm.sleep=false");
  apply_override(document, "description=a=b");
  EXPECT_EQ(document["lsystem"]["iterations"], 6);
  EXPECT_EQ(document["lsystem"]["grammar"], "trees/oak.lsys");
  EXPECT_EQ(document["wind"]["keys"][0]["speed"], 3);
  EXPECT_EQ(document["hsm"]["sleep"], false);
  EXPECT_EQ(document["description"], "a=b");
}

TEST(SceneOverrides, IndexesAndAppendsToArrays) {
  Json document = Json::parse(R"({"outputs": [{"format": "hdf5", "path": "a.h5"}]})");
  apply_override(document, "outputs.0.path=b.h5");
  apply_override(document, "outputs.1.format=obj");
  EXPECT_EQ(document["outputs"][0]["path"], "b.h5");
  EXPECT_EQ(document["outputs"][1]["format"], "obj");
  try {
    apply_override(document, "outputs.5.path=x");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "--set 'outputs.5.path=x': /outputs/5 is not an index of an array of 2 elements (0 ... 2, 2 appending one)");
  }
}

// An array the scene lacks has no element 1 to set: the whole array is what is missing.
TEST(SceneOverrides, AnElementOfAnAbsentArrayAsksForTheWholeArray) {
  Json document = Json::parse(R"({"hsm": {}})");
  try {
    apply_override(document, "hsm.gravity.1=-5");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "--set 'hsm.gravity.1=-5': /hsm/gravity is not in the scene, so its element 1 cannot be "
                           "set alone: set the whole array (--set 'hsm.gravity=[...]')");
  }
  apply_override(document, "outputs.0.format=obj");  // element 0 starts the array
  EXPECT_EQ(document["outputs"][0]["format"], "obj");
}

TEST(SceneOverrides, RefusesToDescendIntoAScalar) {
  Json document = Json::parse(R"({"time": {"fps": 24}})");
  try {
    apply_override(document, "time.fps.x=1");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "--set 'time.fps.x=1': /time/fps is 24, not an object");
  }
}

TEST(SceneOverrides, EmptyNameIsRefused) {
  Json document = Json::object();
  EXPECT_THROW(apply_override(document, "time..fps=1"), InputError);
  EXPECT_THROW(apply_override(document, "=1"), InputError);
}

// A --set value or path nested past the limit is refused, at any depth, before it reaches the
// document (a deep document crashed every recursive walk over it).
TEST(SceneOverrides, DeepValuesAndPathsAreRefused) {
  Json document = Json::object();
  const std::string deep = std::string(50'000, '[') + std::string(50'000, ']');
  try {
    apply_override(document, "tree=" + deep);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "--set 'tree=" + std::string(52, '[') + "...':1:256: JSON nested deeper than "
              "256 levels of arrays and objects (counted from the scene's root; /tree takes 1 of them); no scene "
              "needs more");
  }
  std::string path = "tree";
  for (int i = 0; i < 50'000; ++i) path += ".a";
  EXPECT_THROW(apply_override(document, path + "=1"), InputError);
  EXPECT_THROW(apply_override(document, "tree={\"a\": 1, \"a\": 2}"), InputError);
  EXPECT_EQ(document, Json::object());
  apply_override(document, "tree=" + std::string(255, '[') + std::string(255, ']'));  // at the limit
}

TEST(SceneText, RepeatedKeysAreRefused) {
  try {
    load_scene_text("{\"seed\": 3,\n\"seed\": 7}", "s.json", "/scenes", {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "s.json:2:1: /seed: duplicate key (first at line 1, again at line 2); keep one of them");
  }
}

TEST(SceneResolved, DefaultsAreFilledIn) {
  const Scene scene = load_scene_text(kValid, "s.json", "/scenes", {});
  EXPECT_EQ(scene.resolved["time"]["fps"], 24);
  EXPECT_EQ(scene.resolved["time"]["substeps"], scene.time.substeps);
  EXPECT_EQ(scene.resolved["seed"], 1);
  EXPECT_TRUE(scene.resolved["outputs"].is_array());
}

}  // namespace
}  // namespace treeanim
