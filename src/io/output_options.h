#pragma once
// Scene /outputs elements (docs/scene.md). Owned by io/; fields are added as sinks need.
#include <filesystem>
#include <string>

#include "common/scene_reader.h"

namespace treeanim {

struct OutputOptions {
  std::string format;              // one of kOutputFormats
  std::filesystem::path path;      // as written in the scene; resolved by OutputSet
  int frame_step = 1;              // write every k-th frame
  int compression = 0;             // hdf5: 0 none, 1..9 shuffle + deflate level
  bool velocities = false;         // hdf5: also write /frames/velocities
  bool normals = false;            // hdf5, obj, gltf, glb: per-frame vertex normals
  double quantize = 0;             // hdf5: m, > 0 stores displacements as integers of this step
  size_t texture_width = 0;        // vat: texels per row; 0 = as many as vertices, at most 8192
  size_t max_joints = 0;           // skinned_glb: joints at most; 0 = one per cluster
  bool vat_half = false;           // vat: half-float textures (else float)
  size_t max_page_bytes = 64 << 20;  // html: the page's size limit (key max_mib)
  std::string pointer;             // "/outputs/N", for messages about this element
};

// The formats /outputs/N/format accepts.
inline const char* const kOutputFormats[] = {"hdf5", "obj", "gltf", "glb", "pc2", "mdd", "vat", "skinned_glb", "html"};

// One element of /outputs => options. Keys that do not apply to the format are left
// undeclared, so the scene reader reports them as unknown.
OutputOptions read_output_options(SceneObject element);

}  // namespace treeanim
