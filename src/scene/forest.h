#pragma once
// Scene section /forest (docs/scene.md "forest"): many trees in one wind, each a variant (its
// own grammar and tree options) with its own seed, place, rotation about +Y and scale. The trees
// are listed explicitly and/or scattered by seeded dart throwing; no tree model is built here.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "lsystem/lsystem_options.h"
#include "scene/scene_reader.h"
#include "scene/species.h"
#include "sim/sim_options.h"
#include "tree/tree_options.h"

namespace treeanim {

// /forest/variants/N: one kind of tree.
struct ForestVariant {
  std::string name;        // unique in the forest; names the variant in the manifest
  double weight = 1;       // share of the scattered trees
  LsystemOptions lsystem;  // its own /lsystem, else the scene's
  TreeOptions tree;        // its own /tree, else the scene's
  HsmOptions hsm;          // the scene's /hsm, under the variant's species and its own /hsm
  std::string pointer;     // "/forest/variants/2" (messages)
  Json resolved;           // the variant's resolved object (what a tree's own scene records)
  // A species variant: the species and the height it grows to at a tree's scale 1; a tree's
  // scale keeps it within the species' range of heights, as /tree/scale does a lone tree.
  const Species* species = nullptr;
  double height = 0;       // m
};

// One tree of the forest.
struct ForestTree {
  std::string id;                                     // unique, safe in a file name: what {tree} becomes
  uint32_t variant = 0;                               // index into Forest::variants
  uint64_t seed = 1;                                  // the tree's derivation seed
  Eigen::Vector3d position = Eigen::Vector3d::Zero(); // m, world position of the tree's base
  double rotation = 0;                                // degrees about +Y (counter-clockwise seen from above)
  double scale = 1;                                   // uniform size factor, grown into the model
  std::string pointer;                                // "/forest/trees/3" or "/forest/scatter" (messages)
};

struct Forest {
  std::vector<ForestVariant> variants;
  std::vector<ForestTree> trees;  // explicit trees first, then the scattered ones
  double spacing = 0;             // m, least horizontal distance between two trees
};

// The scene's top-level sections that variants without their own fall back to.
struct ForestDefaults {
  uint64_t seed = 1;                     // /seed
  const LsystemOptions* lsystem = nullptr;  // null when the scene has no top-level /lsystem
  const TreeOptions* tree = nullptr;
  const HsmOptions* hsm = nullptr;
  const SpeciesChoice* species = nullptr;   // /species: a variant without its own grammar grows it
};

// /forest => the forest, every tree placed. Throws InputError (exit 2) naming the JSON pointer:
// no trees, an unknown variant, two ids alike, explicit trees closer than the spacing (both
// pointers), a scatter that does not fit (how many did).
Forest read_forest(SceneObject section, const ForestDefaults& defaults);

// The placeholder of output paths that becomes each tree's id.
inline constexpr const char* kTreePlaceholder = "{tree}";

}  // namespace treeanim
