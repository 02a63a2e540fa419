#pragma once
// Scene /outputs elements (docs/scene.md), read by scene/ (src/scene/output_section.h); the keys
// each format takes are its row of the format table (src/output/output_formats.h).
#include <cstddef>
#include <filesystem>
#include <string>

namespace treeanim {

struct OutputFormatRow;

struct OutputOptions {
  const OutputFormatRow* format = nullptr;  // its row of output_formats(), set by the reader
  std::filesystem::path path;      // as written in the scene; resolved by OutputSet
  int frame_step = 1;              // write every k-th frame
  int compression = 0;             // hdf5: 0 none, 1..9 shuffle + deflate level
  bool velocities = false;         // hdf5: also write /frames/velocities
  bool normals = false;            // hdf5, obj, gltf, glb, usd: per-frame vertex normals (default on for gltf, glb)
  double quantize = 0;             // hdf5: m, > 0 stores displacements as integers of this step
  size_t texture_width = 0;        // vat: texels per row; 0 = as many as vertices, at most 8192
  size_t max_joints = 0;           // skinned_glb, skinned usd: joints at most; 0 = one per cluster
  bool vat_half = false;           // vat: half-float textures (else float)
  bool skinned = false;            // usd: UsdSkel joints and keys instead of points per frame
  size_t max_page_bytes = 64 << 20;  // html: the page's size limit (key max_mib)
  std::string pointer;             // "/outputs/N", for messages about this element
  std::string source;              // the scene's name, or the override that set the path ("" when unknown), before the pointer in messages

  // "scene.json: /outputs/N": what a message about this element begins with, as the scene's own.
  std::string where() const { return source.empty() ? pointer : source + ": " + pointer; }
};

}  // namespace treeanim
