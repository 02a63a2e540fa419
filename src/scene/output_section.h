#pragma once
// Scene /outputs elements (docs/scene.md) => the output options; the keys a format takes are
// its row of the format table (output/output_formats.h).
#include "output/output_options.h"
#include "scene/scene_reader.h"

namespace treeanim {

// One element of /outputs => options. Keys that do not apply to the format are left
// undeclared, so the scene reader reports them as unknown.
OutputOptions read_output_options(SceneObject element);

}  // namespace treeanim
