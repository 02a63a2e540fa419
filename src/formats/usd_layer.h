#pragma once
// What the tree's USD layers share (docs/outputs.md "USD layer"), the points form
// (formats/usd_sink.cpp) and the UsdSkel form (formats/skinned_usd_sink.cpp): the layer's
// name, the stage's metadata, time samples, the mesh's rest attributes and its materials.
#include <array>
#include <cstddef>
#include <string>

#include "formats/frame_sink.h"
#include "formats/outputs.h"
#include "output/output_options.h"
#include "tree/surface_materials.h"
#include "tree/tree_model.h"

namespace treeanim {

// The stage's metadata, with `custom` as its customLayerData when not empty: the frames written
// are the time codes, one per frame at the bake's rate.
std::string usd_layer_header(const BakeInfo& info, const FrameSelection& selection, const std::string& custom);

// One time sample of an array: "<indent><time code>: [...],\n".
void append_usd_sample(std::string& out, const char* indent, long long code, const float* values, size_t count,
                       int width);

// The mesh's topology, texture coordinates, rest points and (with_normals) rest normals: the
// attributes both forms share.
std::string usd_mesh_rest_attributes(const TreeModel& model, bool with_normals);

// The bark and leaf subsets of the mesh, each bound to its material.
std::string usd_material_subsets(const TreeModel& model, const std::string& indent);

// The two UsdPreviewSurface materials under /Tree/Materials.
std::string usd_materials(const std::array<SurfaceMaterial, kMaterialCount>& surfaces);

}  // namespace treeanim
