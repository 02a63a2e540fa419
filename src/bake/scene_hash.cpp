#include "bake/scene_hash.h"

#include <cinttypes>
#include <cstdint>
#include <cstdio>

namespace treeanim {

std::string scene_hash(const std::string& scene_json, const std::string& generator) {
  uint64_t hash = 0xcbf29ce484222325ull;
  auto mix = [&](const std::string& text) {
    for (unsigned char c : text) {
      hash ^= c;
      hash *= 0x100000001b3ull;
    }
  };
  mix(scene_json);
  mix("\n");
  mix(generator);
  char text[32];
  std::snprintf(text, sizeof text, "fnv1a64:%016" PRIx64, hash);
  return text;
}

}  // namespace treeanim
