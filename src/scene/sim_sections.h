#pragma once
// Scene sections /hsm and /wind (docs/scene.md) => the sim stage's options, validated with
// messages that carry the JSON pointer; a wind CSV is read here too, so its errors
// (file:line) surface with the other input errors.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "scene/scene_reader.h"
#include "sim/sim_options.h"

namespace treeanim {

// /hsm section => solver options; a key the section leaves out takes its value from `defaults`.
HsmOptions read_hsm_options(SceneObject section, HsmOptions defaults = {});
// /wind section => wind options. scene_seed is the top-level /seed (turbulence default).
WindOptions read_wind_options(SceneObject section, uint64_t scene_seed);

// The wind's maximum speed, m/s (docs/scene.md `wind.keys`): a volume's voxels are held to it too.
constexpr double kMaxWindSpeed = 113;

// CSV text (header "time,speed,dx,dy,dz[,gust]") => keys. `name` prefixes errors
// ("name:line: ..."). Throws InputError.
std::vector<WindKey> parse_wind_csv(std::string_view text, const std::string& name);

}  // namespace treeanim
