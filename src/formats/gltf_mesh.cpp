#include "formats/gltf_mesh.h"

#include <algorithm>
#include <exception>
#include <limits>
#include <ostream>
#include <streambuf>
#include <utility>

#include "common/errors.h"
#include "files/io_failure.h"
#include "files/output_file.h"

namespace treeanim {

namespace {

// A stream's bytes into an OutputFile; the first failure is kept for the caller (a stream
// swallows what its buffer throws) and ends the writing.
class OutputFileBuffer final : public std::streambuf {
 public:
  explicit OutputFileBuffer(OutputFile& file) : file_(file) {}
  void rethrow() const {
    if (failure_) std::rethrow_exception(failure_);
  }

 protected:
  std::streamsize xsputn(const char* data, std::streamsize count) override {
    if (failure_) return 0;
    try {
      file_.write(data, static_cast<size_t>(count));
      return count;
    } catch (...) {
      failure_ = std::current_exception();
      return 0;
    }
  }
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    const char byte = traits_type::to_char_type(c);
    return xsputn(&byte, 1) == 1 ? c : traits_type::eof();
  }

 private:
  OutputFile& file_;
  std::exception_ptr failure_;
};

}  // namespace

void write_glb(const tinygltf::Model& gltf, const std::filesystem::path& temporary,
               const std::filesystem::path& target) {
  OutputFile file(temporary, target);
  OutputFileBuffer buffer(file);
  std::ostream stream(&buffer);
  tinygltf::TinyGLTF writer;
  const bool written = writer.WriteGltfSceneToStream(&gltf, stream, false, true);
  buffer.rethrow();
  if (!written || !stream) throw OutputError(io_failure(target, "tinygltf could not write the GLB"));
  file.close();
}

GltfBuilder::GltfBuilder(tinygltf::Model& gltf) : gltf_(gltf) { gltf_.buffers.emplace_back(); }

int GltfBuilder::accessor(const void* data, size_t bytes, int component, size_t count, int type, int target) {
  auto& buffer = gltf_.buffers[0].data;
  buffer.resize((buffer.size() + 3) / 4 * 4, 0);  // every view 4-byte aligned
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.size();
  view.byteLength = bytes;
  view.target = target;
  const auto* begin = static_cast<const unsigned char*>(data);
  buffer.insert(buffer.end(), begin, begin + bytes);
  gltf_.bufferViews.push_back(view);
  tinygltf::Accessor a;
  a.bufferView = int(gltf_.bufferViews.size() - 1);
  a.componentType = component;
  a.count = count;
  a.type = type;
  gltf_.accessors.push_back(a);
  return int(gltf_.accessors.size() - 1);
}

int GltfBuilder::floats(const std::vector<float>& values, int type, int components, int target) {
  return accessor(values.data(), 4 * values.size(), TINYGLTF_COMPONENT_TYPE_FLOAT, values.size() / size_t(components),
                  type, target);
}

void set_bounds(tinygltf::Model& gltf, int index, const std::vector<float>& values, int components) {
  std::vector<double> low(size_t(components), std::numeric_limits<double>::max());
  std::vector<double> high(size_t(components), -std::numeric_limits<double>::max());
  for (size_t i = 0; i < values.size(); ++i) {
    low[i % size_t(components)] = std::min(low[i % size_t(components)], double(values[i]));
    high[i % size_t(components)] = std::max(high[i % size_t(components)], double(values[i]));
  }
  gltf.accessors[size_t(index)].minValues = low;
  gltf.accessors[size_t(index)].maxValues = high;
}

MaterialIndices material_indices(const TreeModel& model) {
  MaterialIndices indices;
  indices.corners.reserve(model.triangles.size());
  const auto groups = material_triangles(model);
  for (size_t m = 0; m < kMaterialCount; ++m) {
    for (uint32_t t : groups[m])
      indices.corners.insert(indices.corners.end(), model.triangles.begin() + 3 * t, model.triangles.begin() + 3 * t + 3);
    indices.counts[m] = 3 * groups[m].size();
  }
  return indices;
}

nlohmann::json gltf_materials_json(const std::array<SurfaceMaterial, kMaterialCount>& materials) {
  nlohmann::json list = nlohmann::json::array();
  for (const SurfaceMaterial& m : materials)
    list.push_back({{"name", m.name},
                    {"pbrMetallicRoughness",
                     {{"baseColorFactor", {m.base_color[0], m.base_color[1], m.base_color[2], 1.0}},
                      {"metallicFactor", 0.0},
                      {"roughnessFactor", m.roughness}}},
                    {"doubleSided", m.double_sided}});
  return list;
}

int add_tree_mesh(GltfBuilder& add, const TreeModel& model, const BakeInfo& info,
                  std::map<std::string, int> attributes) {
  tinygltf::Model& gltf = add.gltf();
  const size_t first_material = gltf.materials.size();
  for (const SurfaceMaterial& m : info.materials) {
    tinygltf::Material material;
    material.name = m.name;
    material.pbrMetallicRoughness.baseColorFactor = {m.base_color[0], m.base_color[1], m.base_color[2], 1.0};
    material.pbrMetallicRoughness.metallicFactor = 0.0;
    material.pbrMetallicRoughness.roughnessFactor = m.roughness;
    material.doubleSided = m.double_sided;
    gltf.materials.push_back(material);
  }
  if (!info.vertex_colors.empty())
    attributes["COLOR_0"] = add.floats(info.vertex_colors, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER);
  const MaterialIndices indices = material_indices(model);
  tinygltf::Mesh mesh;
  mesh.name = "tree";
  size_t first_corner = 0;
  for (size_t m = 0; m < kMaterialCount; ++m) {
    const size_t count = indices.counts[m];
    if (count == 0) continue;  // glTF accessors hold at least one element
    tinygltf::Primitive primitive;
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    primitive.material = int(first_material + m);
    primitive.attributes = attributes;
    primitive.indices = add.accessor(indices.corners.data() + first_corner, 4 * count,
                                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, count, TINYGLTF_TYPE_SCALAR,
                                     TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    mesh.primitives.push_back(primitive);
    first_corner += count;
  }
  gltf.meshes.push_back(mesh);
  return int(gltf.meshes.size() - 1);
}

void add_tree_scene(GltfBuilder& add, const TreeModel& model, const BakeInfo& info,
                    std::map<std::string, int> attributes) {
  tinygltf::Model& gltf = add.gltf();
  tinygltf::Node node;
  node.mesh = add_tree_mesh(add, model, info, std::move(attributes));
  node.name = "tree";
  gltf.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(int(gltf.nodes.size() - 1));
  gltf.scenes.push_back(scene);
  gltf.defaultScene = 0;
  gltf.asset.version = "2.0";
  gltf.asset.generator = info.generator;
}

std::vector<float> gltf_uvs(const TreeModel& model) {
  std::vector<float> uvs(2 * model.vertex_count());
  for (size_t v = 0; v < model.vertex_count(); ++v) {
    uvs[2 * v] = model.uvs(0, long(v));
    uvs[2 * v + 1] = 1.0f - model.uvs(1, long(v));
  }
  return uvs;
}

}  // namespace treeanim
