#include "formats/output_estimate.h"

#include <algorithm>

#include "formats/sink_factories.h"
#include "output/output_formats.h"

namespace treeanim {

double estimated_output_bytes(const OutputOptions& output, size_t vertices, size_t triangles, size_t clusters,
                              long long frames) {
  if (PlannedBytes* planned = find_planned_bytes(output.format->name))
    return planned(output, vertices, triangles, clusters, frames);
  const double written = double((frames + output.frame_step - 1) / output.frame_step);
  const OutputFormatRow& format = *output.format;
  return written * format.frame_bytes(output, vertices, triangles, clusters) +
         (format.fixed_bytes ? format.fixed_bytes(output, vertices, triangles, clusters) : 0.0);
}

}  // namespace treeanim
