#pragma once
// Stage entry point: L-system options => derived module string => turtle => Skeleton.
#include <cstddef>

#include "lsystem/lsystem_options.h"
#include "lsystem/skeleton.h"

namespace treeanim {

struct GrowthStats {
  size_t modules = 0;  // modules in the derived string (after decomposition)
  int iterations = 0;  // derivation steps applied
};

// options (grammar file or inline rules, defines, seed, step) => skeleton (scene units).
// Throws InputError with file:line:column for grammar errors, and at the module cap.
Skeleton grow_skeleton(const LsystemOptions& options, GrowthStats* stats);

}  // namespace treeanim
