#pragma once
// Sizes of the animated and the skinned GLB, known before simulating, so a bake that cannot fit is
// refused early: upper bounds of the files written (tests/io/test_glb_sinks.cpp compares them).
#include <cstdint>

#include "formats/outputs.h"
#include "tree/tree_model.h"

namespace treeanim {

// A GLB states its total length as uint32: 4 GiB - 1 bytes at most.
constexpr uint64_t kGlbMaxBytes = 0xFFFFFFFFull;

// Bytes of the animated GLB of `info.frame_count` frames written every `frame_step`-th, with
// morph-target normals or without.
uint64_t animated_glb_bytes(const TreeModel& model, const BakeInfo& info, int frame_step, bool normals = false);

// Bytes of the skinned GLB of `frames` written frames and `joints` joints (a loop's closing key,
// vertex colours and the per-frame error in the extras counted).
uint64_t skinned_glb_bytes(const TreeModel& model, size_t joints, uint64_t frames);

}  // namespace treeanim
