#include "output/output_estimate.h"

#include <algorithm>

#include "output/output_formats.h"

namespace treeanim {

double estimated_output_bytes(const OutputOptions& output, size_t vertices, size_t triangles, size_t clusters,
                              long long frames) {
  const double written = double((frames + output.frame_step - 1) / output.frame_step);
  const double bytes = written * output.format->frame_bytes(output, vertices, triangles, clusters);
  return output.format->limit_bytes ? std::min(bytes, output.format->limit_bytes(output)) : bytes;
}

}  // namespace treeanim
