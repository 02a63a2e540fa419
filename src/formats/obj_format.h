#pragma once
// Wavefront OBJ written directly (not through assimp, whose exporter merges equal positions
// and reorders vertices): vertex k of every file is vertex k of the TreeModel.
#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "tree/surface_materials.h"
#include "tree/tree_model.h"

namespace treeanim {

// The part every OBJ of a bake shares: "mtllib <mtl_name>", "vt" lines (one per vertex) and
// "f v/vt" lines, or "f v/vt/vn" lines when every file has a "vn" line per vertex, with a
// "usemtl" line wherever the triangle's material changes.
std::string obj_shared_lines(const TreeModel& model, const std::string& mtl_name, bool with_normals = false);
// The materials file the OBJ files of an output name: "newmtl" per material, Kd linear RGB (as
// Blender's importer reads it), the PBR extension's Pr and Pm, and Ns for readers without it.
void write_mtl_file(const std::filesystem::path& temporary, const std::filesystem::path& target,
                    std::string_view comment, const std::array<SurfaceMaterial, kMaterialCount>& materials);
// Writes one OBJ: a comment line, "v" lines of `positions` (V*3 floats, shortest round-trip
// text), "vn" lines of `normals` (V*3, or empty for none), then `shared`. Throws OutputError
// naming `target`.
void write_obj_file(const std::filesystem::path& temporary, const std::filesystem::path& target,
                    std::string_view comment, const std::vector<float>& positions, const std::string& shared,
                    const std::vector<float>& normals = {});

}  // namespace treeanim
