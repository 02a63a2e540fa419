// SceneReader: typed reads, defaults written into the resolved scene, exact error messages.
#include <gtest/gtest.h>

#include "common/errors.h"
#include "common/did_you_mean.h"
#include "scene/scene_reader.h"

namespace treeanim {
namespace {

// Runs `read` on the root of `text` and returns the InputError message ("" if none).
template <typename Read>
std::string reader_error_of(const std::string& text, Read read) {
  Json document = Json::parse(text);
  try {
    SceneReader reader(document, "/scenes", "s.json");
    SceneObject root = reader.root();
    read(root);
    reader.check_unknown_keys();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SceneReader, DefaultsAreWrittenIntoTheResolvedScene) {
  Json document = Json::parse(R"({"time": {"fps": 30}})");
  SceneReader reader(document, "/scenes");
  SceneObject time = reader.root().object("time");
  EXPECT_EQ(time.number("fps", 24, Range::positive()), 30);
  EXPECT_EQ(time.integer("frames", 120, 1, 1000), 120);
  EXPECT_EQ(reader.root().object("wind").boolean("on", true), true);
  EXPECT_EQ(document["time"]["frames"], 120);
  EXPECT_EQ(document["wind"]["on"], true);
  EXPECT_EQ(document["time"]["fps"], 30);
}

TEST(SceneReader, ANullKeyIsNotGivenAndNotUnknown) {
  // null takes the default like a missing key (docs/scene.md): has() says not given, and the
  // key is still one of the object's, not an unknown one.
  Json document = Json::parse(R"({"forest": null, "wind": {"volume": null, "speed": 3}})");
  SceneReader reader(document, "/scenes");
  SceneObject root = reader.root();
  EXPECT_FALSE(root.has("forest"));
  EXPECT_FALSE(root.has("lsystem"));
  SceneObject wind = root.object("wind");
  EXPECT_FALSE(wind.has("volume"));
  EXPECT_TRUE(wind.has("speed"));
  EXPECT_NO_THROW(reader.check_unknown_keys());
}

TEST(SceneReader, UnknownKeySuggestsTheClosestValidKey) {
  EXPECT_EQ(
      reader_error_of(R"({"wind": {"sped": 3}})", [](SceneObject& root) { root.object("wind").number("speed", 1); }),
      "s.json: /wind/sped: unknown key (did you mean /wind/speed?)");
}

TEST(SceneReader, UnknownKeyFarFromAnyValidKeyGetsNoSuggestion) {
  EXPECT_EQ(reader_error_of(R"({"wind": {"zzzzzzzz": 3}})",
                            [](SceneObject& root) { root.object("wind").number("speed", 1); }),
            "s.json: /wind/zzzzzzzz: unknown key");
}

TEST(SceneReader, UnknownKeyInsideArrayElement) {
  EXPECT_EQ(reader_error_of(R"({"outputs": [{"format": "hdf5"}, {"formt": "obj"}]})",
                            [](SceneObject& root) {
                              for (SceneObject o : root.array_of_objects("outputs")) o.optional_string("format");
                            }),
            "s.json: /outputs/1/formt: unknown key (did you mean /outputs/1/format?)");
}

TEST(SceneReader, WrongTypeNamesPointerValueAndExpectation) {
  EXPECT_EQ(reader_error_of(R"({"time": {"fps": "fast"}})",
                            [](SceneObject& root) { root.object("time").number("fps", 24, Range::positive()); }),
            "s.json: /time/fps: expected a number > 0, got \"fast\"");
}

TEST(SceneReader, OutOfRangeNamesTheRange) {
  EXPECT_EQ(reader_error_of(R"({"hsm": {"alpha": 1.5}})",
                            [](SceneObject& root) { root.object("hsm").number("alpha", 0.5, Range::between(0, 1)); }),
            "s.json: /hsm/alpha: expected a number in [0, 1], got 1.5");
}

TEST(SceneReader, IntegerRejectsFractions) {
  EXPECT_EQ(reader_error_of(R"({"time": {"frames": 2.5}})",
                            [](SceneObject& root) { root.object("time").integer("frames", 1, 1, 100); }),
            "s.json: /time/frames: expected an integer in [1, 100], got 2.5");
}

TEST(SceneReader, ChoiceListsTheChoicesAndSuggests) {
  EXPECT_EQ(reader_error_of(R"({"format": "hdf"})",
                            [](SceneObject& root) {
                              root.choice("format", "hdf5", {"hdf5", "obj"});
                            }),
            "s.json: /format: expected one of \"hdf5\", \"obj\", got \"hdf\" (did you mean \"hdf5\"?)");
  EXPECT_EQ(reader_error_of(R"({"format": 5})",
                            [](SceneObject& root) {
                              root.choice("format", "hdf5", {"hdf5", "obj"});
                            }),
            "s.json: /format: expected one of \"hdf5\", \"obj\", got 5");
}

TEST(SceneReader, Vector3NeedsThreeNumbers) {
  EXPECT_EQ(reader_error_of(R"({"direction": [1, 0]})",
                            [](SceneObject& root) {
                              root.vector3("direction", {1, 0, 0});
                            }),
            "s.json: /direction: expected an array of 3 finite numbers, got [1,0]");
}

TEST(SceneReader, SectionMustBeAnObject) {
  EXPECT_EQ(reader_error_of(R"({"tree": 3})", [](SceneObject& root) { root.object("tree"); }),
            "s.json: /tree: expected an object, got 3");
}

TEST(SceneReader, ArrayElementsMustBeObjects) {
  EXPECT_EQ(reader_error_of(R"({"outputs": ["a.h5"]})", [](SceneObject& root) { root.array_of_objects("outputs"); }),
            "s.json: /outputs/0: expected an object, got \"a.h5\"");
}

TEST(SceneReader, PathsResolveAgainstTheSceneFolder) {
  Json document = Json::parse(R"({"a": "g/x.lsys", "b": "/abs/y.lsys"})");
  SceneReader reader(document, "/scenes/here");
  SceneObject root = reader.root();
  EXPECT_EQ(root.optional_path("a")->string(), "/scenes/here/g/x.lsys");
  EXPECT_EQ(root.optional_path("b")->string(), "/abs/y.lsys");
  EXPECT_FALSE(root.optional_path("c").has_value());
}

TEST(SceneReader, RawValuesAreNotCheckedForUnknownKeys) {
  EXPECT_EQ(reader_error_of(R"({"defines": {"anything": 1}})", [](SceneObject& root) { root.raw("defines"); }), "");
}

TEST(SceneReader, PointerTokensAreEscaped) {
  EXPECT_EQ(reader_error_of(R"({"a/b": 1})", [](SceneObject&) {}), "s.json: /a~1b: unknown key");
}

TEST(SceneReader, ClosestMatch) {
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(closest_match("substep", {"substeps", "fps"}), "substeps");
  EXPECT_EQ(closest_match("xyz", {"substeps", "fps"}), "");
  // Neighbours swapped are one edit; case is ignored before the letters are compared.
  EXPECT_EQ(edit_distance("fromat", "format"), 1u);
  EXPECT_EQ(edit_distance("axoim", "axiom"), 1u);
  EXPECT_EQ(closest_match("Z", {"x", "y", "z"}), "z");
  EXPECT_EQ(closest_match("GLB", {"hdf5", "glb", "obj"}), "glb");
  // A short word is not turned into another by two edits.
  EXPECT_EQ(closest_match("fbx", {"hdf5", "glb", "obj"}), "");
  // A word too far from any is taken as the abbreviation of the one it begins, if one.
  EXPECT_EQ(closest_match("dir", {"time", "speed", "direction", "gust"}), "direction");
  EXPECT_EQ(closest_match("turb", {"turbulence_length", "turbulence_intensity"}), "");
  EXPECT_EQ(closest_match("di", {"direction"}), "");
}

}  // namespace
}  // namespace treeanim
