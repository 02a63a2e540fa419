// libFuzzer target: wind CSV text => keys. Bad files must end in InputError, and the keys
// of a good one must be usable (finite, unit directions, strictly increasing times).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "common/errors.h"
#include "scene/sim_sections.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace treeanim;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const std::vector<WindKey> keys = parse_wind_csv(text, "fuzz.csv");
    for (size_t i = 0; i < keys.size(); ++i) {
      const WindKey& k = keys[i];
      const bool usable = std::isfinite(k.time) && k.speed >= 0 && std::isfinite(k.speed) &&
                          std::abs(k.direction.norm() - 1) < 1e-9 && k.gust >= 0 &&
                          (i == 0 || k.time > keys[i - 1].time);
      if (!usable) __builtin_trap();
    }
  } catch (const InputError&) {
  }
  return 0;
}
