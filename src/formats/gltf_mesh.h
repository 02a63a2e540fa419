#pragma once
// What the glTF writers share: views and accessors over one growing buffer (tinygltf), and the
// tree's mesh as glTF: one set of vertex attributes shared by a primitive per material (its own
// index accessor), so vertex order and count stay those of the TreeModel; the materials; and,
// when the bake has them, the per-leaf colour factors as COLOR_0.
#include <tiny_gltf.h>

#include <array>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "formats/outputs.h"
#include "tree/surface_materials.h"
#include "tree/tree_model.h"

namespace treeanim {

// `gltf` as one binary glTF in `temporary`, every write checked (tinygltf's own file writer
// reports no failed write: a full disk left a cut file). Throws OutputError naming `target`.
void write_glb(const tinygltf::Model& gltf, const std::filesystem::path& temporary, const std::filesystem::path& target);

// Appends views and accessors to a tinygltf model over one growing buffer.
class GltfBuilder {
 public:
  explicit GltfBuilder(tinygltf::Model& gltf);
  // One view over a copy of `bytes` bytes at `data` (4-byte aligned) and an accessor of it.
  int accessor(const void* data, size_t bytes, int component, size_t count, int type, int target = 0);
  int floats(const std::vector<float>& values, int type, int components, int target = 0);
  tinygltf::Model& gltf() { return gltf_; }

 private:
  tinygltf::Model& gltf_;
};

// Per-component bounds of float accessor `index` holding `values` (glTF asks them of POSITION and
// animation inputs).
void set_bounds(tinygltf::Model& gltf, int index, const std::vector<float>& values, int components);

// The model's triangle corners grouped by material (material 0's triangles, then material 1's,
// each group in model order): the index data of the primitives.
struct MaterialIndices {
  std::vector<uint32_t> corners;                     // (T*3) vertex ids
  std::array<size_t, kMaterialCount> counts{};       // corners of each material
};
MaterialIndices material_indices(const TreeModel& model);

// The materials as glTF material objects (metallic-roughness; base colour linear).
nlohmann::json gltf_materials_json(const std::array<SurfaceMaterial, kMaterialCount>& materials);

// Adds the materials, the index accessors, COLOR_0 (when info.vertex_colors is not empty) and a
// mesh "tree" with a primitive per material that has triangles, each with `attributes`;
// returns the mesh's index.
int add_tree_mesh(GltfBuilder& add, const TreeModel& model, const BakeInfo& info,
                  std::map<std::string, int> attributes);

// add_tree_mesh, then one node "tree" holding it, the default scene of that node and the asset
// (glTF 2.0, info's generator): a whole file of the still mesh.
void add_tree_scene(GltfBuilder& add, const TreeModel& model, const BakeInfo& info,
                    std::map<std::string, int> attributes);

// The model's UVs as glTF wants them: (V*2), v running down the image (OBJ's and ours run up).
std::vector<float> gltf_uvs(const TreeModel& model);

}  // namespace treeanim
