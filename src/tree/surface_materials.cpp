#include "tree/surface_materials.h"

#include <algorithm>
#include <cmath>

#include "common/random.h"

namespace treeanim {

namespace {

// Purpose key of the leaf colour draws (RandomStream::keyed), apart from the grammar's own.
constexpr uint64_t kLeafColorPurpose = 0x6c6561665f636f6cull;  // "leaf_col"

SurfaceMaterial material(const char* name, const Eigen::Vector3d& srgb, double roughness, bool double_sided) {
  SurfaceMaterial m;
  m.name = name;
  for (int c = 0; c < 3; ++c) {
    m.base_color_srgb[size_t(c)] = float(srgb[c]);
    m.base_color[size_t(c)] = float(srgb_to_linear(srgb[c]));
  }
  m.roughness = roughness;
  m.double_sided = double_sided;
  return m;
}

}  // namespace

double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

std::array<SurfaceMaterial, kMaterialCount> surface_materials(const TreeOptions& options) {
  // Bark is rough and matte; a leaf's cuticle gives it a soft sheen.
  return {material(kMaterialNames[kMaterialBark], options.bark_color, 0.8, false),
          material(kMaterialNames[kMaterialLeaf], options.leaf_color, 0.6, true)};
}

std::vector<float> leaf_color_factors(const TreeModel& model, double variation, uint64_t seed) {
  if (variation <= 0) return {};
  std::vector<float> factors(3 * model.vertex_count(), 1.0f);
  std::vector<std::array<float, 3>> leaf(model.leaf_count());
  for (size_t l = 0; l < leaf.size(); ++l) {
    RandomStream random = RandomStream::keyed(seed, kLeafColorPurpose, 0, l);
    // Darker leaves inside a crown, and a shift towards yellow (less green and blue) or towards
    // blue-green (less red); factors stay <= 1, as glTF's COLOR_0 in [0, 1] asks.
    const double brightness = 1.0 - 0.45 * variation * random.uniform();
    const double tint = variation * (2.0 * random.uniform() - 1.0);
    const double warm = std::max(tint, 0.0), cool = std::max(-tint, 0.0);
    leaf[l] = {float(brightness * (1.0 - 0.5 * cool)), float(brightness * (1.0 - 0.25 * warm)),
               float(brightness * (1.0 - 0.5 * warm))};
  }
  for (size_t v = 0; v < model.vertex_count(); ++v)
    if (model.vertex_leaf[v] >= 0)
      for (size_t c = 0; c < 3; ++c) factors[3 * v + c] = leaf[size_t(model.vertex_leaf[v])][c];
  return factors;
}

std::array<std::vector<uint32_t>, kMaterialCount> material_triangles(const TreeModel& model) {
  std::array<std::vector<uint32_t>, kMaterialCount> groups;
  for (size_t t = 0; t < model.triangle_count(); ++t) groups[model.triangle_material[t]].push_back(uint32_t(t));
  return groups;
}

}  // namespace treeanim
