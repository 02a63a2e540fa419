#include "io/output_estimate.h"

#include <algorithm>

namespace treeanim {

double estimated_output_bytes(const OutputOptions& output, size_t vertices, size_t triangles, long long frames) {
  const double written = double((frames + output.frame_step - 1) / output.frame_step);
  const double vectors = 12.0 * double(vertices);  // one float32 [x, y, z] per vertex
  const double normals = output.normals ? vectors : 0;
  if (output.format == "hdf5")  // quantized: int16 displacements
    return written * ((output.quantize > 0 ? 0.5 : 1.0) * vectors + (output.velocities ? vectors : 0) + normals);
  if (output.format == "obj")  // text: "v x y z" lines of ~32 characters, faces of ~24
    return written * (32.0 * double(vertices) + (output.normals ? 36.0 * double(vertices) : 0) + 24.0 * double(triangles));
  if (output.format == "gltf")  // a file per frame: positions, triangles
    return written * (vectors + normals + 12.0 * double(triangles));
  if (output.format == "glb" || output.format == "pc2" || output.format == "mdd") return written * (vectors + normals);
  if (output.format == "vat")  // offsets and normals, RGBA texels
    return written * (output.vat_half ? 8.0 : 16.0) * 2.0 * double(vertices);
  if (output.format == "html")  // float32 positions in base64, reduced to fit the page's limit
    return std::min(written * vectors * 4.0 / 3.0, double(output.max_page_bytes));
  return 0;  // skinned_glb: keys per joint, small beside the mesh
}

}  // namespace treeanim
