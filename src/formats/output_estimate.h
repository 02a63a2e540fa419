#pragma once
// What an output will take on disk, estimated before baking (treeanim farm plan): the bytes of
// its per-frame data, uncompressed, from the mesh size and the frames it writes, and what it
// writes once (the rest mesh, joints). Compression is left out: an upper bound for the frames,
// within a few percent for plain HDF5, PC2 and MDD. A format that plans its whole size before
// simulating (the preview page, under its limit) gives that plan instead: an upper bound of all
// it writes.
#include <cstddef>

#include "output/output_options.h"

namespace treeanim {

// output options, mesh size (vertices, triangles, clusters), frames of the bake => estimated bytes of the output.
double estimated_output_bytes(const OutputOptions& output, size_t vertices, size_t triangles, size_t clusters,
                              long long frames);

}  // namespace treeanim
