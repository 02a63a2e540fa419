#pragma once
// Size of the animated GLB, known before simulating, so a bake that cannot fit is refused early.
#include <cstdint>

#include "formats/outputs.h"
#include "tree/tree_model.h"

namespace treeanim {

// A GLB states its total length as uint32: 4 GiB - 1 bytes at most.
constexpr uint64_t kGlbMaxBytes = 0xFFFFFFFFull;

// Bytes of the animated GLB of `info.frame_count` frames written every `frame_step`-th, with
// morph-target normals or without.
uint64_t animated_glb_bytes(const TreeModel& model, const BakeInfo& info, int frame_step, bool normals = false);

}  // namespace treeanim
