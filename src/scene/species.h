#pragma once
// The species library (docs/species.md): named presets of grammar, tree geometry, leaves,
// colours and wood, from grammars/species/ (embedded in the binary at build time).
#include <optional>
#include <string>
#include <vector>

#include "common/json_text.h"
#include "lsystem/lsystem_options.h"
#include "scene/scene_reader.h"
#include "sim/sim_options.h"
#include "tree/tree_options.h"

namespace treeanim {

struct Species {
  std::string name;    // what a scene's "species" names: english_oak
  std::string common;  // English oak
  std::string latin;   // Quercus robur
  std::string habit;   // one line on its shape
  double default_height = 0, min_height = 0, max_height = 0;  // m; the grammar grows default_height at scale 1
  double sway_frequency = 0;  // Hz, its first sway frequency at default_height, plucked (tests/species holds it to that)
  GrammarText grammar;  // named "grammars/species/<file>" in messages
  TreeOptions tree;     // the preset's /tree at default_height
  Json hsm;             // the preset's /hsm keys (its wood), read over a scene's own
  Json sources;         // where the wood, leaf and architecture values come from
};

// => "English oak (english_oak) grows from 10 to 28 m, got ", for a refusal outside its range.
std::string range_text(const Species& s);
// A bound of a range at six significant digits, as messages write numbers, rounded into the
// range (up for its lower end, down for its upper): the rounded upper bound of a scale was refused.
double inward(double bound, bool lower);

// Every species, in the table's order (parsed once; a malformed table is a build defect).
const std::vector<Species>& species_library();

// A scene's choice: which species, grown to what height.
struct SpeciesChoice {
  const Species* species = nullptr;
  double height = 0;          // m
  bool height_given = false;  // the scene gave /species/height (not the species' default)
  // The factor every length of the preset is grown by (scaled_tree_options).
  double factor() const { return height / species->default_height; }
};

// `parent`'s "species" ("NAME" or {"name": NAME, "height": METRES}) => the choice, or nullopt
// when absent. Throws InputError naming the pointer: an unknown name (with the names and the
// closest), a height outside the species' range (naming it).
std::optional<SpeciesChoice> read_species(SceneObject& parent);

// A species' height and a /tree/scale set the same size: refuses both unless they agree (as in a
// resolved scene, which records both). Throws InputError at tree/scale.
void check_species_scale(const SpeciesChoice& choice, SceneObject tree);
// The choice's tree options, grown to its height: the defaults a scene's /tree is read over.
TreeOptions species_tree(const SpeciesChoice& choice);
// `base` with the species' /hsm keys over it: the defaults a scene's /hsm is read over.
HsmOptions species_hsm(const SpeciesChoice& choice, const HsmOptions& base);

}  // namespace treeanim
