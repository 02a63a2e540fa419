#include "formats/obj_format.h"

#include <charconv>

#include "files/output_file.h"

namespace treeanim {

namespace {

// Appends the shortest text that reads back as exactly `value`.
void append_number(std::string& out, float value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

void append_index(std::string& out, uint32_t value) {
  char buffer[16];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

}  // namespace

std::string obj_shared_lines(const TreeModel& model, const std::string& mtl_name, bool with_normals) {
  std::string out;
  out.reserve(24 * model.vertex_count() + 40 * model.triangle_count());
  out += "mtllib " + mtl_name + "\n";
  // Without normals of its own the mesh is one smoothing group, so that importers shade the
  // bark smooth from the vertices' normals (Blender imported it faceted, a ring of eight flats).
  if (!with_normals) out += "s 1\n";
  for (size_t v = 0; v < model.vertex_count(); ++v) {
    out += "vt ";
    append_number(out, model.uvs(0, long(v)));
    out += ' ';
    append_number(out, model.uvs(1, long(v)));
    out += '\n';
  }
  for (size_t t = 0; t < model.triangle_count(); ++t) {
    if (t == 0 || model.triangle_material[t] != model.triangle_material[t - 1]) {
      out += "usemtl ";
      out += kMaterialNames[model.triangle_material[t]];
      out += '\n';
    }
    out += 'f';
    for (int corner = 0; corner < 3; ++corner) {
      const uint32_t index = model.triangles[3 * t + corner] + 1;  // OBJ counts from 1
      out += ' ';
      append_index(out, index);
      out += '/';
      append_index(out, index);
      if (with_normals) {
        out += '/';
        append_index(out, index);
      }
    }
    out += '\n';
  }
  return out;
}

void write_mtl_file(const std::filesystem::path& temporary, const std::filesystem::path& target,
                    std::string_view comment, const std::array<SurfaceMaterial, kMaterialCount>& materials) {
  std::string text = "# ";
  text += comment;
  text += '\n';
  for (const SurfaceMaterial& m : materials) {
    // Ns from the roughness as Blender's importer inverts it (roughness = 1 - sqrt(Ns / 1000)).
    const float shininess = float(1000.0 * (1.0 - m.roughness) * (1.0 - m.roughness));
    text += std::string("\nnewmtl ") + m.name + "\nKd";
    for (float c : m.base_color) {
      text += ' ';
      append_number(text, c);
    }
    text += "\nNs ";
    append_number(text, shininess);
    text += "\nPr ";
    append_number(text, float(m.roughness));
    // Ks 0.5: the specular Blender's importer sets from it, as its glTF importer does for the
    // GLB's materials (without Ks, illum 2 made it 1, the OBJ glossier than the same GLB).
    text += "\nKs 0.5 0.5 0.5\nPm 0\nd 1\nillum 2\n";
  }
  OutputFile file(temporary, target);
  file.write(text);
  file.close();
}

void write_obj_file(const std::filesystem::path& temporary, const std::filesystem::path& target,
                    std::string_view comment, const std::vector<float>& positions, const std::string& shared,
                    const std::vector<float>& normals) {
  std::string text;
  text.reserve(comment.size() + 3 + 12 * (positions.size() + normals.size()));
  text += "# ";
  text += comment;
  text += '\n';
  for (const auto& [keyword, values] : {std::pair{"v", &positions}, std::pair{"vn", &normals}}) {
    for (size_t i = 0; i < values->size(); i += 3) {
      text += keyword;
      for (size_t a = 0; a < 3; ++a) {
        text += ' ';
        append_number(text, (*values)[i + a]);
      }
      text += '\n';
    }
  }
  OutputFile file(temporary, target);
  file.write(text);
  file.write(shared);
  file.close();
}

}  // namespace treeanim
