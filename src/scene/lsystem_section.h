#pragma once
// Scene section /lsystem (docs/scene.md) => the lsystem stage's options.
#include <cstdint>

#include "lsystem/lsystem_options.h"
#include "scene/scene_reader.h"

namespace treeanim {

// /lsystem section => options. scene_seed is the top-level /seed (the default for lsystem.seed);
// species_grammar, when given, is grown if the section names no grammar of its own.
LsystemOptions read_lsystem_options(SceneObject section, uint64_t scene_seed,
                                    const GrammarText* species_grammar = nullptr);

}  // namespace treeanim
