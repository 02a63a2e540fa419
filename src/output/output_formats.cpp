// The table of output formats (output/output_formats.h). A new format: its sink's file
// (formats/<format>_sink.cpp), a row here and its sink's line in formats/sink_factories.cpp (and
// its entries in docs/outputs.md and docs/design.md, which tests compare with the table).
#include "output/output_formats.h"

#include <algorithm>
#include <string>

namespace treeanim {

namespace {

using Type = OutputKey::Type;

// Bytes of one float32 [x, y, z] per vertex.
double vector_bytes(size_t vertices) { return 12.0 * double(vertices); }

double normal_bytes(const OutputOptions& o, size_t vertices) { return o.normals ? vector_bytes(vertices) : 0; }

// The key of the formats that write per-frame vertex normals on request.
const OutputKey kNormalsKey{.name = "normals",
                            .type = Type::kBoolean,
                            .store = [](OutputOptions& o, double v) { o.normals = v != 0; }};

// The same key on by default: glTF viewers shade a mesh without normals flat.
const OutputKey kSmoothNormalsKey{.name = "normals",
                                  .type = Type::kBoolean,
                                  .fallback = 1,
                                  .store = [](OutputOptions& o, double v) { o.normals = v != 0; }};

// Positions and, when asked, normals of every vertex: the GLB's morph targets, PC2 and MDD.
double vector_frame_bytes(const OutputOptions& o, size_t vertices, size_t, size_t) {
  return vector_bytes(vertices) + normal_bytes(o, vertices);
}

// An OBJ file of the whole mesh: "v x y z" lines of about 33 characters (shortest round-trip
// floats), "vn" of about 37, "vt u v" of up to 20, and a face's three corners of two or three
// indices of as many digits as the vertex count has (on the demo, 2026-11-30: 32.6, 36.4, 13
// and 31 or 46 characters a line; the estimate is 8-11 % over).
double obj_file_bytes(const OutputOptions& o, size_t vertices, size_t triangles, size_t) {
  const double digits = double(std::to_string(vertices).size()), indices = o.normals ? 3.0 : 2.0;
  return (34.0 + (o.normals ? 38.0 : 0) + 20.0) * double(vertices) +
         (2.0 + 3.0 * indices * (digits + 1.0)) * double(triangles);
}

// The rest OBJ beside a PC2 or MDD cache: positions, UVs and faces.
double rest_obj_bytes(const OutputOptions&, size_t vertices, size_t triangles, size_t clusters) {
  return obj_file_bytes(OutputOptions{}, vertices, triangles, clusters);
}

// A GLB's mesh, written once: positions, normals, UVs and leaf colours (44 bytes a vertex), the
// triangles' indices (12).
double glb_mesh_bytes(const OutputOptions&, size_t vertices, size_t triangles, size_t) {
  return 45.0 * double(vertices) + 12.0 * double(triangles);
}

// Joints of a skinned output: one per cluster, or max_joints when fewer.
double joint_count(const OutputOptions& o, size_t clusters) {
  return double(o.max_joints > 0 ? std::min(o.max_joints, clusters) : clusters);
}

// A skinned GLB's keys: a float translation and rotation per joint.
double skinned_frame_bytes(const OutputOptions& o, size_t, size_t, size_t clusters) {
  return 28.0 * joint_count(o, clusters);
}

// A skinned GLB's mesh with four joints and weights a vertex (24 bytes), and per joint its
// node, inverse bind matrix and animation channels (about 620 bytes with their JSON).
double skinned_mesh_bytes(const OutputOptions& o, size_t vertices, size_t triangles, size_t clusters) {
  return glb_mesh_bytes(o, vertices, triangles, clusters) + 24.0 * double(vertices) + 620.0 * joint_count(o, clusters);
}

// The joints a skinned output takes at most.
const OutputKey kMaxJointsKey{.name = "max_joints",
                              .type = Type::kInteger,
                              .optional = true,
                              .lo = 1,
                              .hi = 65535,
                              .store = [](OutputOptions& o, double v) { o.max_joints = size_t(v); }};

const std::vector<OutputFormatRow> kFormats = {
    {.name = "hdf5",
     .keys = {{.name = "compression",
               .type = Type::kInteger,
               .lo = 0,
               .hi = 9,
               .store = [](OutputOptions& o, double v) { o.compression = int(v); }},
              {.name = "velocities",
               .type = Type::kBoolean,
               .store = [](OutputOptions& o, double v) { o.velocities = v != 0; }},
              // 1 nm is far below float32's resolution of a tree's coordinates; 1 m is no shape at all.
              {.name = "quantize",
               .type = Type::kNumber,
               .optional = true,
               .lo = 1e-9,
               .hi = 1.0,
               .store = [](OutputOptions& o, double v) { o.quantize = v; }},
              kNormalsKey},
     .leaf_flags = true,
     // quantized: int16 displacements
     .frame_bytes = [](const OutputOptions& o, size_t vertices, size_t, size_t) {
       const double vectors = vector_bytes(vertices);
       return (o.quantize > 0 ? 0.5 : 1.0) * vectors + (o.velocities ? vectors : 0) + normal_bytes(o, vertices);
     },
     // the rest mesh, UVs and clusters: 36 bytes a vertex and 12 a triangle, fitted to the demo
     // and table1-13548 (2026-11-30); and 32 KiB of HDF5's own headers and B-trees and the first
     // chunk of frame times, which a small bake's file is mostly (a one-frame demo of 527
     // vertices: 63 KB written, 33 KB estimated without them)
     .fixed_bytes = [](const OutputOptions&, size_t vertices, size_t triangles, size_t) {
       return 36.0 * double(vertices) + 12.0 * double(triangles) + 32768.0;
     }},
    {.name = "obj",
     .keys = {kNormalsKey},
     .frame_bytes = obj_file_bytes,
     .fixed_bytes = obj_file_bytes},  // the rest OBJ
    {.name = "gltf",
     .keys = {kSmoothNormalsKey},
     // a file per frame, the whole mesh: positions, UVs (8 bytes a vertex), leaf colours (12, at
     // most), triangles, and its JSON and headers (about 2 KB)
     .frame_bytes = [](const OutputOptions& o, size_t vertices, size_t triangles, size_t) {
       return vector_bytes(vertices) + normal_bytes(o, vertices) + 20.0 * double(vertices) + 12.0 * double(triangles) +
              2048.0;
     }},
    {.name = "glb", .keys = {kSmoothNormalsKey}, .frame_bytes = vector_frame_bytes, .fixed_bytes = glb_mesh_bytes},
    {.name = "pc2", .frame_bytes = vector_frame_bytes, .fixed_bytes = rest_obj_bytes},
    {.name = "mdd", .frame_bytes = vector_frame_bytes, .fixed_bytes = rest_obj_bytes},
    {.name = "vat",
     .keys = {{.name = "texture_width",
               .type = Type::kInteger,
               .lo = 0,
               .hi = 8192,
               .store = [](OutputOptions& o, double v) { o.texture_width = size_t(v); }},
              {.name = "precision",
               .type = Type::kChoice,
               .choices = {"float", "half"},
               .store = [](OutputOptions& o, double v) { o.vat_half = v == 1; }}},
     .always_normals = true,  // the normals texture
     // offsets and normals, RGBA texels
     .frame_bytes = [](const OutputOptions& o, size_t vertices, size_t, size_t) {
       return (o.vat_half ? 8.0 : 16.0) * 2.0 * double(vertices);
     },
     .fixed_bytes = glb_mesh_bytes},  // the mesh the textures move
    {.name = "skinned_glb",
     .keys = {kMaxJointsKey},
     .skinned = true,
     .frame_bytes = skinned_frame_bytes,
     .fixed_bytes = skinned_mesh_bytes},
    {.name = "usd",
     .keys = {kNormalsKey,
              {.name = "skinned",
               .type = Type::kBoolean,
               .store = [](OutputOptions& o, double v) { o.skinned = v != 0; }},
              kMaxJointsKey},
     .path_extension = ".usda",
     .file_kind = "a usd output is a text layer",
     // text: ~36 characters a point, ~38 a normal; skinned: ~96 a joint's translation and rotation
     .frame_bytes = [](const OutputOptions& o, size_t vertices, size_t, size_t clusters) {
       return o.skinned ? 96.0 * joint_count(o, clusters) : (36.0 + (o.normals ? 38.0 : 0.0)) * double(vertices);
     },
     // text, fitted to the demo and table1-13548 (2026-11-30): the rest mesh, about 40 characters a
     // vertex and 36 a triangle; skinned, 24 a vertex's joints and weights and 320 a joint more
     .fixed_bytes = [](const OutputOptions& o, size_t vertices, size_t triangles, size_t clusters) {
       return 40.0 * double(vertices) + 36.0 * double(triangles) +
              (o.skinned ? 24.0 * double(vertices) + 320.0 * joint_count(o, clusters) : 0.0);
     }},
    {.name = "html",
     .keys = {{.name = "max_mib",
               .type = Type::kInteger,
               .fallback = 64,
               .lo = 2,
               .hi = 64,
               .store = [](OutputOptions& o, double v) { o.max_page_bytes = size_t(v) << 20; }}},
     // float32 positions in base64; the page's whole size, planned to fit its limit, is its
     // sink's (formats/output_estimate.h)
     .frame_bytes = [](const OutputOptions&, size_t vertices, size_t, size_t) { return vector_bytes(vertices) * 4.0 / 3.0; }},
};

}  // namespace

std::span<const OutputFormatRow> output_formats() { return kFormats; }

bool joint_per_cluster(const OutputOptions& options, size_t clusters) {
  return (options.format->skinned || options.skinned) && joint_count(options, clusters) == double(clusters);
}

const OutputFormatRow* find_output_format(const std::string& name) {
  for (const OutputFormatRow& row : kFormats)
    if (name == row.name) return &row;
  return nullptr;
}

}  // namespace treeanim
