// The species library (docs/species.md): a species' preset under a scene's own keys, its height,
// forest variants of several species, the resolved scene that bakes the same tree again, and the
// refusals.
#include <gtest/gtest.h>

#include <set>

#include "input_error_of.h"
#include "scene/scene.h"
#include "scene/species.h"

namespace treeanim {
namespace {

Scene load_species(const std::string& text) { return load_scene_text(text, "s.json", "/scenes", {}); }

const Species& named(const std::string& name) {
  for (const Species& s : species_library())
    if (s.name == name) return s;
  throw std::runtime_error("no species " + name);
}

TEST(SpeciesLibrary, HoldsTenNamedSpeciesEachWithItsGrammarAndRange) {
  const std::vector<Species>& library = species_library();
  EXPECT_GE(library.size(), 10u);
  std::set<std::string> names;
  for (const Species& s : library) {
    EXPECT_TRUE(names.insert(s.name).second) << s.name;
    EXPECT_EQ(s.grammar.name, "grammars/species/" + s.name + ".lsys");
    EXPECT_NE(s.grammar.text.find("derivation length:"), std::string::npos) << s.name;
    EXPECT_LE(s.min_height, s.default_height) << s.name;
    EXPECT_LE(s.default_height, s.max_height) << s.name;
    EXPECT_TRUE(s.hsm.contains("youngs_modulus")) << s.name << ": its wood";
    for (const char* source : {"wood", "leaves", "architecture"})
      EXPECT_TRUE(s.sources.contains(source)) << s.name << " cites no source for its " << source;
  }
}

TEST(SpeciesScene, APresetGivesGrammarTreeAndWood) {
  const Species& oak = named("english_oak");
  const Scene scene = load_species(R"({"species": "english_oak"})");
  ASSERT_TRUE(scene.lsystem.library_grammar);
  EXPECT_EQ(scene.lsystem.library_grammar->name, oak.grammar.name);
  EXPECT_EQ(scene.tree.wood_density, oak.tree.wood_density);
  EXPECT_EQ(scene.tree.leaf.size, oak.tree.leaf.size);
  EXPECT_EQ(scene.tree.bark_color, oak.tree.bark_color);
  EXPECT_EQ(scene.hsm.youngs_modulus, oak.hsm["youngs_modulus"].get<double>());
  EXPECT_EQ(scene.tree.scale, 1.0);
}

TEST(SpeciesScene, EveryKeyOfTheSceneStillApplies) {
  const Scene scene = load_species(R"({"species": "english_oak", "tree": {"leaf": {"size": 0.5}, "ring_sides": 5},
                               "hsm": {"youngs_modulus": 3e9, "precision": "float"}})");
  EXPECT_EQ(scene.tree.leaf.size, 0.5);
  EXPECT_EQ(scene.tree.ring_sides, 5);
  EXPECT_EQ(scene.tree.leaf.aspect, named("english_oak").tree.leaf.aspect);
  EXPECT_EQ(scene.hsm.youngs_modulus, 3e9);
  EXPECT_EQ(scene.hsm.precision, Precision::kFloat);
  // A grammar of the scene's own replaces the species'.
  const Scene own = load_species(R"({"species": "english_oak", "lsystem": {"axiom": "F", "iterations": 0}})");
  EXPECT_FALSE(own.lsystem.library_grammar);
  EXPECT_EQ(own.tree.wood_density, named("english_oak").tree.wood_density);
}

TEST(SpeciesScene, HeightGrowsEveryLengthAndTheResolvedSceneBakesTheSameTree) {
  const Species& oak = named("english_oak");
  const double height = 0.5 * (oak.min_height + oak.max_height);
  const Scene scene = load_species(R"({"species": {"name": "english_oak", "height": )" + std::to_string(height) + "}}");
  const double factor = height / oak.default_height;
  EXPECT_DOUBLE_EQ(scene.tree.scale, oak.tree.scale * factor);
  EXPECT_DOUBLE_EQ(scene.tree.leaf.size, oak.tree.leaf.size * factor);
  EXPECT_DOUBLE_EQ(scene.tree.trunk_radius, oak.tree.trunk_radius * factor);
  const Scene again = load_species(scene.resolved.dump());
  EXPECT_EQ(again.tree.scale, scene.tree.scale);
  EXPECT_EQ(again.tree.leaf.size, scene.tree.leaf.size);
  EXPECT_EQ(again.hsm.youngs_modulus, scene.hsm.youngs_modulus);
  EXPECT_EQ(again.lsystem.library_grammar->text, oak.grammar.text);
  EXPECT_EQ(again.resolved, scene.resolved);
}

// A /tree/scale without a height sets the size as the height does, in either form of the choice,
// and the resolved scene (which records both) loads again to the same tree.
TEST(SpeciesScene, AScaleWithoutAHeightGrowsTheWholePreset) {
  const Species& oak = named("english_oak");
  ASSERT_EQ(oak.tree.scale, 1.0);
  const double factor = 1.25;  // 22.5 m, within the oak's 10-28
  for (const std::string species : {R"("english_oak")", R"({"name": "english_oak"})"}) {
    const Scene scene = load_species(R"({"species": )" + species + R"(, "tree": {"scale": 1.25}})");
    EXPECT_EQ(scene.tree.scale, 1.25) << species;
    EXPECT_DOUBLE_EQ(scene.tree.leaf.size, oak.tree.leaf.size * factor) << species;
    EXPECT_DOUBLE_EQ(scene.tree.trunk_radius, oak.tree.trunk_radius * factor) << species;
    const Scene again = load_species(scene.resolved.dump());
    EXPECT_EQ(again.tree.scale, scene.tree.scale) << species;
    EXPECT_EQ(again.tree.leaf.size, scene.tree.leaf.size) << species;
    EXPECT_EQ(again.tree.trunk_radius, scene.tree.trunk_radius) << species;
    EXPECT_EQ(again.resolved, scene.resolved) << species;
  }
  std::ostringstream range;
  range << "/tree/scale: English oak (english_oak) grows from " << oak.min_height << " to " << oak.max_height
        << " m, got ";
  EXPECT_NE(
      input_error_of([&] { load_species(R"({"species": "english_oak", "tree": {"scale": 100}})"); }).find(range.str()),
      std::string::npos);
}

TEST(SpeciesScene, ForestVariantsOfSeveralSpeciesEachKeepTheirWood) {
  const Scene forest = load_species(R"({"hsm": {"precision": "float"}, "forest": {
      "variants": [{"name": "oak", "species": "english_oak"},
                   {"name": "spruce", "species": {"name": "norway_spruce", "height": 12}, "hsm": {"damping_ratio": 0.3}}],
      "trees": [{"variant": "oak"}, {"variant": "spruce", "position": [10, 0, 0]}]},
      "outputs": [{"format": "hdf5", "path": "{tree}.h5"}]})");
  const Species& oak = named("english_oak");
  const Species& spruce = named("norway_spruce");
  for (size_t i = 0; i < 2; ++i) {
    const Scene tree = tree_scene(forest, i);
    const Species& species = i == 0 ? oak : spruce;
    ASSERT_TRUE(tree.lsystem.library_grammar);
    EXPECT_EQ(tree.lsystem.library_grammar->name, species.grammar.name);
    EXPECT_EQ(tree.hsm.youngs_modulus, species.hsm["youngs_modulus"].get<double>());
    EXPECT_EQ(tree.hsm.precision, Precision::kFloat) << "the scene's /hsm stays under the species'";
    EXPECT_EQ(tree.tree.wood_density, species.tree.wood_density);
    // Its own resolved scene bakes it again alike.
    const Scene again = tree_scene(load_species(tree.resolved.dump()), 0);
    EXPECT_EQ(again.hsm.youngs_modulus, tree.hsm.youngs_modulus);
    EXPECT_EQ(again.hsm.damping_ratio, tree.hsm.damping_ratio);
    EXPECT_EQ(again.tree.scale, tree.tree.scale);
  }
  EXPECT_EQ(tree_scene(forest, 1).hsm.damping_ratio, 0.3);
  EXPECT_DOUBLE_EQ(tree_scene(forest, 1).tree.scale, 12 / spruce.default_height);
}

// A variant without a grammar of its own grows the scene's species: its /tree goes over that
// species' tree at the scene's height (it went over a bare default tree, 1 m taller, with the
// full drag share), and its trees' scales keep the species within its heights.
TEST(SpeciesScene, AVariantGrowsTheScenesSpeciesUnderItsOwnTree) {
  const Scene forest = load_species(R"({"species": {"name": "hazel", "height": 4}, "forest": {
      "variants": [{"name": "plain"}, {"name": "leafy", "tree": {"leaf": {"size": 0.2}}}],
      "trees": [{"variant": "plain"}, {"variant": "leafy", "position": [10, 0, 0]}]},
      "outputs": [{"format": "hdf5", "path": "{tree}.h5"}]})");
  const Scene plain = tree_scene(forest, 0), leafy = tree_scene(forest, 1);
  EXPECT_EQ(leafy.tree.scale, plain.tree.scale);
  EXPECT_EQ(leafy.tree.drag_share, plain.tree.drag_share);
  EXPECT_EQ(leafy.tree.wood_density, plain.tree.wood_density);
  EXPECT_EQ(leafy.tree.leaf.size, 0.2);
  EXPECT_EQ(tree_scene(load_species(leafy.resolved.dump()), 0).tree.scale, leafy.tree.scale);
  EXPECT_NE(input_error_of([&] {
              load_species(R"({"species": {"name": "hazel", "height": 4}, "forest": {
                  "variants": [{"name": "leafy", "tree": {"leaf": {"size": 0.2}}}],
                  "trees": [{"variant": "leafy", "scale": 10}]}})");
            }).find("/forest/trees/0/scale: hazel (hazel) grows from 3 to 6.5 m, got 40 m"),
            std::string::npos);
}

TEST(SpeciesScene, BadChoicesNameThePointerAndWhatIsExpected) {
  const Species& oak = named("english_oak");
  const std::string unknown = input_error_of([] { load_species(R"({"species": "oak"})"); });
  EXPECT_NE(unknown.find("s.json: /species: no species \"oak\" (did you mean english_oak?)"), std::string::npos)
      << unknown;
  for (const Species& s : species_library()) EXPECT_NE(unknown.find(s.name), std::string::npos) << unknown;
  EXPECT_NE(input_error_of([] {
              load_species(R"({"species": {"name": "nroway_spruce"}})");
            }).find("/species/name: no species \"nroway_spruce\" (did you mean norway_spruce?)"),
            std::string::npos);
  std::ostringstream range;
  range << "/species/height: English oak (english_oak) grows from " << oak.min_height << " to " << oak.max_height
        << " m, got " << oak.max_height + 1;
  EXPECT_NE(
      input_error_of([&] {
        load_species(R"({"species": {"name": "english_oak", "height": )" + std::to_string(oak.max_height + 1) + "}}");
      }).find(range.str()),
      std::string::npos);
  EXPECT_NE(input_error_of([] {
              load_species(R"({"species": 5})");
            }).find("/species: expected a species' name, or {\"name\": NAME, \"height\": METRES}, got 5"),
            std::string::npos);
  EXPECT_NE(input_error_of([] {
              load_species(R"({"species": {"height": 12}})");
            }).find("/species/name: expected a species' name"),
            std::string::npos);
  EXPECT_NE(input_error_of([] {
              load_species(R"({"species": {"name": "english_oak", "height": 15}, "tree": {"scale": 2}})");
            }).find("/tree/scale: the species' height of 15 m grows it at a scale of "),
            std::string::npos);
  // Productions beside a species and no axiom would be left unread: the species' grammar grows.
  EXPECT_NE(
      input_error_of([] { load_species(R"({"species": "english_oak", "lsystem": {"productions": ["F --> FF"]}})"); })
          .find("/lsystem/productions: inline productions go with /lsystem/axiom; the species' grammar has its "
                "own (give an axiom to grow an inline grammar instead)"),
      std::string::npos);
  EXPECT_NE(input_error_of([] {
              load_species(R"({"species": {"name": "english_oak", "heigth": 15}})");
            }).find("/species/heigth: unknown key (did you mean /species/height?)"),
            std::string::npos);
}

}  // namespace
}  // namespace treeanim
