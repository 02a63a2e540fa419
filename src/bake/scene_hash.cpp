#include "bake/scene_hash.h"

#include <cinttypes>
#include <cstdint>
#include <cstdio>

namespace treeanim {

uint64_t fnv1a64(uint64_t hash, const void* data, size_t bytes) {
  const auto* byte = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; ++i) {
    hash ^= byte[i];
    hash *= 0x100000001b3ull;
  }
  return hash;
}

std::string scene_hash(const std::string& scene_json, const std::string& generator) {
  uint64_t hash = kFnv1aStart;
  auto mix = [&](const std::string& text) { hash = fnv1a64(hash, text.data(), text.size()); };
  mix(scene_json);
  mix("\n");
  mix(generator);
  char text[32];
  std::snprintf(text, sizeof text, "fnv1a64:%016" PRIx64, hash);
  return text;
}

}  // namespace treeanim
