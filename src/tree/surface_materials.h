#pragma once
// The look of a tree's mesh (docs/outputs.md "Materials"): a bark and a leaf material, indexed by
// TriangleMaterial, and per-leaf colour factors so a crown is not one flat green. Every mesh
// output and the preview describe the surfaces with these, so they agree with each other.
#include <array>
#include <cstdint>
#include <vector>

#include "tree/tree_model.h"
#include "tree/tree_options.h"

namespace treeanim {

// A metallic-roughness PBR material (glTF's; metallic 0: wood and leaves are dielectrics).
struct SurfaceMaterial {
  const char* name = "";                  // "bark", "leaf"
  std::array<float, 3> base_color{};      // linear RGB, glTF's baseColorFactor
  std::array<float, 3> base_color_srgb{}; // the same colour as the scene gives it
  double roughness = 1;                   // 0 mirror .. 1 matte
  bool double_sided = false;              // leaves are single sheets seen from both sides
};

// One sRGB component in [0, 1] => linear (IEC 61966-2-1).
double srgb_to_linear(double c);

// tree options => the materials, indexed by TriangleMaterial.
std::array<SurfaceMaterial, kMaterialCount> surface_materials(const TreeOptions& options);

// model, variation in [0, 1], seed => (V*3) linear RGB factors that multiply the base colour of
// the vertex's material (glTF's COLOR_0): 1 on bark, one factor per leaf drawn from (seed, leaf
// index) alone, so it does not depend on thread count or on the other leaves. Empty when
// variation is 0 (no vertex colours are written then).
std::vector<float> leaf_color_factors(const TreeModel& model, double variation, uint64_t seed);

// model => the triangle ids of each material, ascending within each (a glTF primitive's or a
// USD GeomSubset's faces).
std::array<std::vector<uint32_t>, kMaterialCount> material_triangles(const TreeModel& model);

}  // namespace treeanim
