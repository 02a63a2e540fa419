#pragma once
// What ties a checkpoint and a frame journal to their bake: a hash of the resolved scene and the
// treeanim version that bakes it.
#include <string>

namespace treeanim {

// Resolved scene JSON text + generator => "fnv1a64:<16 hex digits>", FNV-1a (64 bit) of the
// scene text, a newline and the generator.
std::string scene_hash(const std::string& scene_json, const std::string& generator);

}  // namespace treeanim
