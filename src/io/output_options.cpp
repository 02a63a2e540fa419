#include "io/output_options.h"

#include <iterator>
#include <vector>

namespace treeanim {

OutputOptions read_output_options(SceneObject element) {
  OutputOptions options;
  options.pointer = element.pointer();
  const std::vector<std::string> formats(std::begin(kOutputFormats), std::end(kOutputFormats));
  if (!element.has("format")) {
    std::string listed;
    for (const std::string& format : formats) listed += (listed.empty() ? "" : ", ") + format;
    element.fail("format", "required (one of " + listed + ")");
  }
  options.format = element.choice("format", "", formats);
  const auto path = element.optional_string("path");
  if (!path || path->empty()) element.fail_expected("path", "a non-empty path string");
  options.path = *path;
  options.frame_step = static_cast<int>(element.integer("frame_step", 1, 1, 1000000));
  if (options.format == "hdf5") {
    options.compression = static_cast<int>(element.integer("compression", 0, 0, 9));
    options.velocities = element.boolean("velocities", false);
    // 1 nm is far below float32's resolution of a tree's coordinates; 1 m is no shape at all.
    options.quantize = element.optional_number("quantize", Range{1e-9, 1.0, false, false}).value_or(0.0);
  }
  if (options.format == "hdf5" || options.format == "obj" || options.format == "gltf" || options.format == "glb")
    options.normals = element.boolean("normals", false);
  if (options.format == "vat") {
    options.normals = true;  // the normals texture
    options.texture_width = static_cast<size_t>(element.integer("texture_width", 0, 0, 8192));
    options.vat_half = element.choice("precision", "float", {"float", "half"}) == "half";
  }
  if (options.format == "skinned_glb")
    options.max_joints = static_cast<size_t>(element.optional_integer("max_joints", 1, 65535).value_or(0));
  if (options.format == "html") options.max_page_bytes = size_t(element.integer("max_mib", 64, 2, 64)) << 20;
  return options;
}

}  // namespace treeanim
