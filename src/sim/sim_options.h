#pragma once
// Scene sections /hsm and /wind (docs/scene.md). Owned by sim/; fields are added as needed.
#include <filesystem>
#include <optional>
#include <vector>

#include "common/scene_reader.h"

namespace treeanim {

struct SimOptions {
  // Filled from /hsm by read_sim_options.
  bool global_matching = true;
};

struct WindOptions {
  // Filled from /wind by read_wind_options (keys or a CSV file, turbulence, drag).
  std::optional<std::filesystem::path> file;
};

// /hsm section => solver options.
SimOptions read_sim_options(SceneObject section);
// /wind section => wind options. scene_seed is the top-level /seed (turbulence default).
// A wind CSV is read here, so its errors (file:line) surface with the other input errors.
WindOptions read_wind_options(SceneObject section, uint64_t scene_seed);

}  // namespace treeanim
