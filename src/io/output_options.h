#pragma once
// Scene /outputs elements (docs/scene.md). Owned by io/; fields are added as sinks need.
#include <filesystem>
#include <string>

#include "common/scene_reader.h"

namespace treeanim {

struct OutputOptions {
  std::string format;              // "hdf5" | "obj" | "gltf" | "glb" | "pc2"
  std::filesystem::path path;      // as written in the scene; resolved by OutputSet
  int frame_step = 1;              // write every k-th frame
};

// One element of /outputs => options.
OutputOptions read_output_options(SceneObject element);

}  // namespace treeanim
