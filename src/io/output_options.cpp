#include "io/output_options.h"

#include <iterator>
#include <vector>

namespace treeanim {

OutputOptions read_output_options(SceneObject element) {
  OutputOptions options;
  options.pointer = element.pointer();
  if (!element.has("format")) element.fail("format", "required (one of hdf5, obj, gltf, glb, pc2)");
  options.format = element.choice("format", "", {std::begin(kOutputFormats), std::end(kOutputFormats)});
  const auto path = element.optional_string("path");
  if (!path || path->empty()) element.fail_expected("path", "a non-empty path string");
  options.path = *path;
  options.frame_step = static_cast<int>(element.integer("frame_step", 1, 1, 1000000));
  if (options.format == "hdf5") {
    options.compression = static_cast<int>(element.integer("compression", 0, 0, 9));
    options.velocities = element.boolean("velocities", false);
  }
  return options;
}

}  // namespace treeanim
