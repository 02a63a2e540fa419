#include "formats/usd_layer.h"

#include <algorithm>
#include <vector>

#include "common/errors.h"
#include "formats/rest_positions_f32.h"
#include "formats/usd_text.h"
#include "formats/vertex_normals.h"

namespace treeanim {

namespace {

void append_color(std::string& out, const std::array<float, 3>& linear) {
  out += '(';
  for (size_t c = 0; c < 3; ++c) {
    if (c > 0) out += ", ";
    append_usd_number(out, linear[c]);
  }
  out += ')';
}

// The USD prim names of the materials and their subsets, by TriangleMaterial.
constexpr const char* kMaterialPrims[kMaterialCount] = {"Bark", "Leaf"};
constexpr const char* kSubsetPrims[kMaterialCount] = {"bark", "leaves"};

}  // namespace

std::string usd_layer_header(const BakeInfo& info, const FrameSelection& selection, const std::string& custom) {
  const long long last = selection.start + (selection.written() - 1) * selection.step;
  std::string out = "#usda 1.0\n(\n";
  if (!custom.empty()) out += "    customLayerData = {\n" + custom + "    }\n";
  out += "    defaultPrim = \"Tree\"\n    doc = " + usd_quoted(info.generator) + "\n";
  out += "    endTimeCode = " + std::to_string(std::max(selection.start, last)) + "\n    framesPerSecond = ";
  append_usd_number(out, info.fps);
  out += "\n    metersPerUnit = 1\n    startTimeCode = " + std::to_string(selection.start) +
         "\n    timeCodesPerSecond = ";
  append_usd_number(out, info.fps);
  out += "\n    upAxis = \"Y\"\n)\n\n";
  return out;
}

void append_usd_sample(std::string& out, const char* indent, long long code, const float* values, size_t count,
                       int width) {
  out += indent;
  out += std::to_string(code) + ": ";
  append_usd_tuples(out, values, count, width);
  out += ",\n";
}

std::string usd_mesh_rest_attributes(const TreeModel& model, bool with_normals) {
  const std::string indent = "        ";
  std::string out = indent + "uniform bool doubleSided = 1\n" + indent + "int[] faceVertexCounts = [";
  for (size_t t = 0; t < model.triangle_count(); ++t) out += t > 0 ? ", 3" : "3";
  out += "]\n" + indent + "int[] faceVertexIndices = ";
  append_usd_ints(out, model.triangles.data(), model.triangles.size());
  out += '\n' + indent + "point3f[] points = ";
  const std::vector<float> rest = rest_positions_f32(model);
  append_usd_tuples(out, rest.data(), model.vertex_count(), 3);
  const std::string vertex_interpolation = " (\n" + indent + "    interpolation = \"vertex\"\n" + indent + ")";
  if (size_t(model.uvs.cols()) == model.vertex_count()) {
    out += '\n' + indent + "texCoord2f[] primvars:st = ";
    append_usd_tuples(out, model.uvs.data(), model.vertex_count(), 2);
    out += vertex_interpolation;
  }
  if (with_normals) {
    out += '\n' + indent + "normal3f[] normals = ";
    const std::vector<float> normals = rest_normals(model);
    append_usd_tuples(out, normals.data(), model.vertex_count(), 3);
    out += vertex_interpolation;
  }
  out += '\n' + indent + "uniform token subdivisionScheme = \"none\"\n" + indent +
         "uniform token subsetFamily:materialBind:familyType = \"partition\"\n";
  return out;
}

std::string usd_material_subsets(const TreeModel& model, const std::string& indent) {
  std::string out;
  const auto triangles = material_triangles(model);
  for (size_t kind = 0; kind < kMaterialCount; ++kind) {
    const std::vector<uint32_t>& faces = triangles[kind];
    if (faces.empty()) continue;  // a leafless tree
    out += '\n' + indent + "def GeomSubset \"" + kSubsetPrims[kind] + "\" (\n" + indent +
           "    prepend apiSchemas = [\"MaterialBindingAPI\"]\n" + indent + ")\n" + indent + "{\n";
    out += indent + "    uniform token elementType = \"face\"\n" + indent +
           "    uniform token familyName = \"materialBind\"\n" + indent + "    int[] indices = ";
    append_usd_ints(out, faces.data(), faces.size());
    out += '\n' + indent + "    rel material:binding = </Tree/Materials/" + kMaterialPrims[kind] + ">\n" + indent +
           "}\n";
  }
  return out;
}

std::string usd_materials(const std::array<SurfaceMaterial, kMaterialCount>& surfaces) {
  std::string out = "\n    def Scope \"Materials\"\n    {\n";
  for (size_t kind = 0; kind < kMaterialCount; ++kind) {
    const std::string name = kMaterialPrims[kind], path = "/Tree/Materials/" + name;
    out += "        def Material \"" + name + "\"\n        {\n";
    out += "            token outputs:surface.connect = <" + path + "/Surface.outputs:surface>\n\n";
    out += "            def Shader \"Surface\"\n            {\n";
    out += "                uniform token info:id = \"UsdPreviewSurface\"\n";
    out += "                color3f inputs:diffuseColor = ";
    append_color(out, surfaces[kind].base_color);
    out += "\n                float inputs:metallic = 0\n                float inputs:roughness = ";
    append_usd_number(out, float(surfaces[kind].roughness));
    out += "\n                token outputs:surface\n            }\n";
    out += "        }\n";
  }
  return out + "    }\n";
}

}  // namespace treeanim
