#include <gtest/gtest.h>

#include "common/errors.h"
#include "output/output_formats.h"
#include "scene/output_section.h"
#include "input_error_of.h"

namespace treeanim {
namespace {

// Reads /outputs/0 of `text` and runs the unknown-key check, as load_scene does.
OutputOptions read_first(const std::string& text, Json* resolved = nullptr) {
  Json document = Json::parse(text);
  SceneReader reader(document, ".");
  auto elements = reader.root().array_of_objects("outputs");
  OutputOptions options = read_output_options(elements.at(0));
  reader.check_unknown_keys();
  if (resolved) *resolved = document;
  return options;
}

std::string outputs_error_of(const std::string& text) {
  return input_error_of([&] { read_first(text); });
}

TEST(OutputOptions, DefaultsAreFilledIn) {
  Json resolved;
  const OutputOptions o = read_first(R"({"outputs": [{"format": "hdf5", "path": "bake.h5"}]})", &resolved);
  EXPECT_EQ(o.format, find_output_format("hdf5"));
  EXPECT_EQ(o.path, "bake.h5");
  EXPECT_EQ(o.frame_step, 1);
  EXPECT_EQ(o.compression, 0);
  EXPECT_FALSE(o.velocities);
  EXPECT_EQ(o.pointer, "/outputs/0");
  EXPECT_EQ(resolved["outputs"][0]["compression"], 0);
  EXPECT_EQ(resolved["outputs"][0]["velocities"], false);
  EXPECT_EQ(resolved["outputs"][0]["frame_step"], 1);
}

TEST(OutputOptions, Hdf5OptionsAreRead) {
  const OutputOptions o = read_first(
      R"({"outputs": [{"format": "hdf5", "path": "b.h5", "compression": 4, "velocities": true, "frame_step": 2}]})");
  EXPECT_EQ(o.compression, 4);
  EXPECT_TRUE(o.velocities);
  EXPECT_EQ(o.frame_step, 2);
}

TEST(OutputOptions, GltfAndGlbCarryNormalsUnlessTurnedOff) {
  Json resolved;
  EXPECT_TRUE(read_first(R"({"outputs": [{"format": "glb", "path": "t.glb"}]})", &resolved).normals);
  EXPECT_EQ(resolved["outputs"][0]["normals"], true);
  EXPECT_TRUE(read_first(R"({"outputs": [{"format": "gltf", "path": "t"}]})").normals);
  EXPECT_FALSE(read_first(R"({"outputs": [{"format": "glb", "path": "t.glb", "normals": false}]})").normals);
  EXPECT_FALSE(read_first(R"({"outputs": [{"format": "obj", "path": "t"}]})").normals);
  EXPECT_FALSE(read_first(R"({"outputs": [{"format": "hdf5", "path": "t.h5"}]})").normals);
}

TEST(OutputOptions, ErrorsNameTheKey) {
  EXPECT_EQ(outputs_error_of(R"({"outputs": [{"path": "b.h5"}]})"),
            "/outputs/0/format: required (one of hdf5, obj, gltf, glb, pc2, mdd, vat, skinned_glb, usd, html)");
  EXPECT_EQ(outputs_error_of(R"({"outputs": [{"format": "hdf"}]})"),
            "/outputs/0/format: expected one of \"hdf5\", \"obj\", \"gltf\", \"glb\", \"pc2\", \"mdd\", \"vat\", "
            "\"skinned_glb\", \"usd\", \"html\", got \"hdf\" "
            "(did you mean \"hdf5\"?)");
  EXPECT_EQ(outputs_error_of(R"({"outputs": [{"format": "obj"}]})"),
            "/outputs/0/path: expected a non-empty path string, got nothing");
  EXPECT_EQ(outputs_error_of(R"({"outputs": [{"format": "obj", "path": ""}]})"),
            "/outputs/0/path: expected a non-empty path string, got \"\"");
  EXPECT_EQ(outputs_error_of(R"({"outputs": [{"format": "hdf5", "path": "b", "compression": 10}]})"),
            "/outputs/0/compression: expected an integer in [0, 9], got 10");
  EXPECT_EQ(outputs_error_of(R"({"outputs": [{"format": "pc2", "path": "b", "frame_step": 0}]})"),
            "/outputs/0/frame_step: expected an integer in [1, 1000000], got 0");
}

TEST(OutputOptions, Hdf5OnlyKeysAreUnknownElsewhere) {
  EXPECT_EQ(outputs_error_of(R"({"outputs": [{"format": "obj", "path": "o", "compression": 4}]})"),
            "/outputs/0/compression: unknown key");
  EXPECT_EQ(outputs_error_of(R"({"outputs": [{"format": "hdf5", "path": "o", "compresion": 4}]})"),
            "/outputs/0/compresion: unknown key (did you mean /outputs/0/compression?)");
}

}  // namespace
}  // namespace treeanim
