#pragma once
// What ties a checkpoint and a frame journal to their bake: a hash of the resolved scene and the
// treeanim version that bakes it.
#include <cstddef>
#include <cstdint>
#include <string>

namespace treeanim {

// FNV-1a (64 bit): its starting value, and a hash so far + `bytes` bytes at `data` => the hash
// of both, byte by byte. A checkpoint keeps the digest of its state to find damage.
constexpr uint64_t kFnv1aStart = 0xcbf29ce484222325ull;
uint64_t fnv1a64(uint64_t hash, const void* data, size_t bytes);

// Resolved scene JSON text + generator => "fnv1a64:<16 hex digits>", FNV-1a (64 bit) of the
// scene text, a newline and the generator.
std::string scene_hash(const std::string& scene_json, const std::string& generator);

}  // namespace treeanim
