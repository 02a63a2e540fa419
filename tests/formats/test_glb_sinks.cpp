// Animated GLB and glTF sequence parsed back byte by byte (header, chunks, accessors, targets,
// one-hot weights, a primitive per material over one vertex set, the materials).
#include <algorithm>
#include <cstring>
#include <nlohmann/json.hpp>

#include "formats/glb_size.h"
#include "formats/vertex_normals.h"
#include "formats_test_support.h"

namespace treeanim {
namespace {

using test::small_frame;
using test::small_info;
using test::small_model;

struct Glb {
  nlohmann::json json;
  std::string bin;
};

uint32_t u32_at(const std::string& bytes, size_t offset) {
  uint32_t v = 0;
  std::memcpy(&v, bytes.data() + offset, 4);
  return v;
}

Glb parse_glb(const std::filesystem::path& path) {
  const std::string bytes = test::read_file(path);
  Glb glb;
  EXPECT_EQ(u32_at(bytes, 0), 0x46546C67u);
  EXPECT_EQ(u32_at(bytes, 4), 2u);
  EXPECT_EQ(u32_at(bytes, 8), bytes.size());
  const uint32_t json_length = u32_at(bytes, 12);
  EXPECT_EQ(u32_at(bytes, 16), 0x4E4F534Au);
  EXPECT_EQ(json_length % 4, 0u);
  glb.json = nlohmann::json::parse(bytes.substr(20, json_length));
  const size_t bin_header = 20 + json_length;
  EXPECT_EQ(u32_at(bytes, bin_header + 4), 0x004E4942u);
  glb.bin = bytes.substr(bin_header + 8, u32_at(bytes, bin_header));
  EXPECT_EQ(bin_header + 8 + glb.bin.size(), bytes.size());
  return glb;
}

// Accessor `index` of a float glTF, as floats.
std::vector<float> accessor_floats(const Glb& glb, size_t index) {
  const auto& accessor = glb.json["accessors"][index];
  const auto& view = glb.json["bufferViews"][accessor["bufferView"].get<size_t>()];
  const size_t components = accessor["type"] == "VEC3" ? 3 : accessor["type"] == "VEC2" ? 2 : 1;
  std::vector<float> values(accessor["count"].get<size_t>() * components);
  const size_t offset = view.value("byteOffset", size_t(0)) + accessor.value("byteOffset", size_t(0));
  std::memcpy(values.data(), glb.bin.data() + offset, 4 * values.size());
  return values;
}

// Index accessor `index`, as vertex ids.
std::vector<uint32_t> accessor_indices(const Glb& glb, size_t index) {
  const auto& accessor = glb.json["accessors"][index];
  EXPECT_EQ(accessor["componentType"], 5125);  // UNSIGNED_INT
  const auto& view = glb.json["bufferViews"][accessor["bufferView"].get<size_t>()];
  std::vector<uint32_t> values(accessor["count"].get<size_t>());
  const size_t offset = view.value("byteOffset", size_t(0)) + accessor.value("byteOffset", size_t(0));
  std::memcpy(values.data(), glb.bin.data() + offset, 4 * values.size());
  return values;
}

// The small model's bark and leaf primitives: the same attributes, its triangles split by
// material, the bake's materials (linear base colours, leaves double-sided).
void expect_materials(const Glb& glb, const BakeInfo& info) {
  const auto& primitives = glb.json["meshes"][0]["primitives"];
  ASSERT_EQ(primitives.size(), 2u);
  EXPECT_EQ(primitives[0]["attributes"], primitives[1]["attributes"]);
  EXPECT_EQ(primitives[0]["material"], 0);
  EXPECT_EQ(primitives[1]["material"], 1);
  EXPECT_EQ(accessor_indices(glb, primitives[0]["indices"]), (std::vector<uint32_t>{1, 2, 0, 0, 2, 3}));
  EXPECT_EQ(accessor_indices(glb, primitives[1]["indices"]), (std::vector<uint32_t>{4, 5, 3}));
  const auto& materials = glb.json["materials"];
  ASSERT_EQ(materials.size(), 2u);
  for (size_t m = 0; m < 2; ++m) {
    EXPECT_EQ(materials[m]["name"], info.materials[m].name);
    const auto& pbr = materials[m]["pbrMetallicRoughness"];
    for (size_t c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(pbr["baseColorFactor"][c].get<float>(), info.materials[m].base_color[c]);
    EXPECT_EQ(pbr["baseColorFactor"][3], 1.0);
    EXPECT_EQ(pbr["metallicFactor"], 0.0);
    EXPECT_FLOAT_EQ(pbr["roughnessFactor"].get<float>(), m == 0 ? 0.8f : 0.6f);
  }
  EXPECT_FALSE(materials[0].value("doubleSided", false));
  EXPECT_TRUE(materials[1].value("doubleSided", false));
  if (info.vertex_colors.empty()) {
    EXPECT_FALSE(primitives[0]["attributes"].contains("COLOR_0"));
  } else {
    EXPECT_EQ(accessor_floats(glb, primitives[0]["attributes"]["COLOR_0"]), info.vertex_colors);
  }
}

// small_info with per-leaf colours: bark white, the leaf's vertices one factor.
BakeInfo coloured_info(long long frames, long long start) {
  BakeInfo info = small_info(frames, start);
  info.vertex_colors = {1, 1, 1, 1, 1, 1, 1, 1, 1, 0.8f, 0.9f, 0.7f, 0.8f, 0.9f, 0.7f, 0.8f, 0.9f, 0.7f};
  return info;
}

class GlbSinks : public test::TempFolder {};

TEST_F(GlbSinks, AnimatedGlbHasOneMorphTargetPerFrame) {
  const TreeModel m = small_model();
  const BakeInfo info = coloured_info(5, 1);
  test::bake({test::output("glb", "anim.glb", 2)}, dir_, m, info);
  EXPECT_EQ(entries(), (std::vector<std::string>{"anim.glb"}));
  // The size check's bound holds, and is not loose by more than the JSON's longest numbers.
  const uint64_t bytes = std::filesystem::file_size(dir_ / "anim.glb");
  EXPECT_LE(bytes, animated_glb_bytes(m, info, 2));
  EXPECT_GT(bytes + 1000, animated_glb_bytes(m, info, 2));
  const Glb glb = parse_glb(dir_ / "anim.glb");
  const auto& primitive = glb.json["meshes"][0]["primitives"][0];
  const std::vector<float> rest = accessor_floats(glb, primitive["attributes"]["POSITION"]);
  EXPECT_EQ(rest, test::rest_f32(m));
  const std::vector<float> uv = accessor_floats(glb, primitive["attributes"]["TEXCOORD_0"]);
  for (long v = 0; v < 6; ++v) {
    EXPECT_EQ(uv[size_t(2 * v)], m.uvs(0, v));
    EXPECT_EQ(uv[size_t(2 * v + 1)], 1.0f - m.uvs(1, v));
  }
  expect_materials(glb, info);
  EXPECT_EQ(glb.json["meshes"][0]["primitives"][1]["targets"], primitive["targets"]);

  const std::vector<long long> frames{1, 3, 5};
  ASSERT_EQ(primitive["targets"].size(), frames.size());
  EXPECT_EQ(glb.json["meshes"][0]["extras"]["targetNames"],
            nlohmann::json({"frame_0001", "frame_0003", "frame_0005"}));
  for (size_t k = 0; k < frames.size(); ++k) {
    const size_t accessor = primitive["targets"][k]["POSITION"];
    const std::vector<float> displacement = accessor_floats(glb, accessor);
    const FrameData frame = small_frame(m, frames[k]);
    for (size_t i = 0; i < displacement.size(); ++i) {
      EXPECT_EQ(displacement[i], frame.positions[i] - rest[i]);
      EXPECT_LE(displacement[i], glb.json["accessors"][accessor]["max"][i % 3].get<float>());
      EXPECT_GE(displacement[i], glb.json["accessors"][accessor]["min"][i % 3].get<float>());
    }
  }
  const auto& sampler = glb.json["animations"][0]["samplers"][0];
  EXPECT_EQ(sampler["interpolation"], "LINEAR");
  EXPECT_EQ(glb.json["animations"][0]["channels"][0]["target"]["path"], "weights");
  const std::vector<float> times = accessor_floats(glb, sampler["input"]);
  EXPECT_EQ(times, (std::vector<float>{float(1 / 24.0), float(3 / 24.0), float(5 / 24.0)}));
  const std::vector<float> weights = accessor_floats(glb, sampler["output"]);
  ASSERT_EQ(weights.size(), 9u);
  for (size_t key = 0; key < 3; ++key)
    for (size_t target = 0; target < 3; ++target) EXPECT_EQ(weights[3 * key + target], key == target ? 1.0f : 0.0f);
}

TEST_F(GlbSinks, SequenceKeepsVerticesAndSplitsFacesByMaterial) {
  const TreeModel m = small_model();
  OutputOptions options = test::output("gltf", "gltf/tree.%03d.glb");
  options.normals = true;
  const BakeInfo info = small_info(2, 0);
  test::bake({options}, dir_, m, info);
  EXPECT_EQ(entries(), (std::vector<std::string>{"gltf", "gltf/tree.000.glb", "gltf/tree.001.glb"}));
  for (long long f : {0, 1}) {
    const Glb glb = parse_glb(dir_ / ("gltf/tree.00" + std::to_string(f) + ".glb"));
    expect_materials(glb, info);
    const auto& attributes = glb.json["meshes"][0]["primitives"][0]["attributes"];
    const FrameData frame = small_frame(m, f);
    EXPECT_EQ(accessor_floats(glb, attributes["POSITION"]), frame.positions);
    const std::vector<float> uv = accessor_floats(glb, attributes["TEXCOORD_0"]);
    for (long v = 0; v < 6; ++v) {
      EXPECT_EQ(uv[size_t(2 * v)], m.uvs(0, v));
      EXPECT_EQ(uv[size_t(2 * v + 1)], 1.0f - m.uvs(1, v));
    }
    std::vector<float> normals;
    vertex_normals(m, frame.positions.data(), rest_normals(m), normals);
    EXPECT_EQ(accessor_floats(glb, attributes["NORMAL"]), normals);
    const auto& position = glb.json["accessors"][attributes["POSITION"].get<size_t>()];
    EXPECT_EQ(position["max"][1].get<float>(), *std::max_element(frame.positions.begin(), frame.positions.end()));
  }
}

// The 4 GiB checks decide before simulating, so their bounds must hold for whatever is written:
// every frame count across the digit counts of the JSON's numbers and target names (frames from
// 9995 on cross into five digits), with and without normals, vertex colours and a loop's closing key.
TEST_F(GlbSinks, AnimatedGlbNeverPassesItsSizeBound) {
  const TreeModel m = small_model();
  for (long long frames : {1, 2, 9, 10, 11, 99, 100, 101, 999, 1000, 1001}) {
    for (bool normals : {false, true}) {
      for (bool loop : {false, true}) {
        BakeInfo info = frames % 2 ? coloured_info(frames, 9995) : small_info(frames, 9995);
        info.loop = loop;
        info.loop_end_time = double(9995 + frames) / 24.0;
        OutputOptions options = test::output("glb", "anim.glb");
        options.normals = normals;
        test::bake({options}, dir_, m, info);
        const uint64_t bytes = std::filesystem::file_size(dir_ / "anim.glb");
        EXPECT_LE(bytes, animated_glb_bytes(m, info, 1, normals)) << frames << " " << normals << " " << loop;
        EXPECT_EQ(parse_glb(dir_ / "anim.glb").json["meshes"][0]["extras"]["targetNames"].size(), size_t(frames));
      }
    }
  }
}

TEST_F(GlbSinks, SkinnedGlbNeverPassesItsSizeBound) {
  const TreeModel m = small_model();
  for (long long frames : {1, 10, 100, 1000, 3000}) {
    for (bool loop : {false, true}) {
      BakeInfo info = coloured_info(frames, 0);
      info.loop = loop;
      info.loop_end_time = double(frames) / 24.0;
      test::bake({test::output("skinned_glb", "skin.glb")}, dir_, m, info);
      EXPECT_LE(std::filesystem::file_size(dir_ / "skin.glb"), skinned_glb_bytes(m, m.cluster_count(), uint64_t(frames)))
          << frames << " " << loop;
    }
  }
}

}  // namespace
}  // namespace treeanim
