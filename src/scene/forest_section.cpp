// /forest => variants and placed trees (docs/scene.md "forest").
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <limits>
#include <optional>
#include <unordered_map>
#include <vector>

#include "common/errors.h"
#include "common/message_text.h"
#include "common/random.h"
#include "scene/forest.h"
#include "scene/forest_layout.h"
#include "scene/lsystem_section.h"
#include "scene/sim_sections.h"
#include "scene/species.h"
#include "scene/tree_section.h"

namespace treeanim {

namespace {

constexpr uint64_t kSeedMask = (1ull << 53) - 1;  // seeds are JSON integers: at most 2^53

// A coordinate on the ground, m: 10 km from the origin a float position (what the outputs store)
// rounds to 1 mm, the least motion of a twig worth baking.
constexpr Range kGround = Range{-1e4, 1e4, false, false};
// A turn about +Y, degrees: a turn past a full one repeats a smaller one, so a larger value is a slip.
constexpr Range kTurn = Range{-360, 360, false, false};
// A tree's size factor: 100 times its variant makes a 1 m sapling near the tallest tree known (116 m).
constexpr Range kTreeScale = Range{0, 100, true, false};

// A name that is safe as (part of) a file name on every system a farm uses.
bool is_file_safe(const std::string& name) {
  if (name.empty() || name.size() > 64 || name[0] == '.' || name[0] == '-') return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
           c == '.';
  });
}

ForestVariant read_variant(SceneObject element, const ForestDefaults& defaults) {
  ForestVariant variant;
  const auto name = element.optional_string("name");
  if (!name || !is_file_safe(*name))
    element.fail_expected("name", "a name of 1 to 64 letters, digits, '_', '-' or '.' (not first)");
  variant.name = *name;
  variant.weight = element.number("weight", 1, Range::non_negative());
  variant.pointer = element.pointer();
  const std::optional<SpeciesChoice> own = read_species(element);
  if (element.has("lsystem") || own)
    variant.lsystem = read_lsystem_options(element.object("lsystem"), defaults.seed,
                                           own ? &own->species->grammar : nullptr);
  else if (defaults.lsystem)
    variant.lsystem = *defaults.lsystem;
  else
    element.fail("lsystem", "expected the variant's grammar (an object like /lsystem, or a species): the scene has "
                            "no top-level /lsystem for it to fall back to");
  // Its own species, or the scene's where it grows the scene's grammar: a variant's /tree then
  // goes over that species' tree, as the top-level /tree does (not over a bare default tree).
  const SpeciesChoice* species = own ? &*own : element.has("lsystem") ? nullptr : defaults.species;
  if (species) {
    if (element.has("tree")) check_species_scale(*species, element.object("tree"));
    variant.species = species->species;
    variant.height = species->height;
  }
  variant.tree = element.has("tree") || own
                     ? read_tree_options(element.object("tree"), species ? species_tree(*species) : TreeOptions{})
                     : *defaults.tree;
  // A species brings its wood; the variant's own /hsm goes over it and over the scene's.
  variant.hsm = element.has("hsm") || own
                    ? read_hsm_options(element.object("hsm"), own ? species_hsm(*own, *defaults.hsm) : *defaults.hsm)
                    : *defaults.hsm;
  variant.resolved = element.json();
  return variant;
}

// The variants, or the scene's own sections as the one variant "default".
std::vector<ForestVariant> read_variants(SceneObject& section, const ForestDefaults& defaults) {
  std::vector<ForestVariant> variants;
  if (!section.has("variants")) {
    section.declare("variants");
    if (!defaults.lsystem)
      section.fail("variants", "expected variants: the scene has no top-level /lsystem to grow its trees from");
    ForestVariant variant;
    variant.name = "default";
    variant.lsystem = *defaults.lsystem;
    if (defaults.species) {  // the scene's species: its trees' scales keep it within its heights
      variant.species = defaults.species->species;
      variant.height = defaults.species->height;
    }
    variant.tree = *defaults.tree;
    variant.hsm = *defaults.hsm;
    variant.resolved = Json{{"name", variant.name}, {"weight", variant.weight}};
    variants.push_back(std::move(variant));
    return variants;
  }
  std::vector<SceneObject> elements = section.array_of_objects("variants");
  if (elements.empty()) section.fail("variants", "expected at least one variant, got []");
  std::unordered_map<std::string, size_t> names;
  for (SceneObject& element : elements) {
    variants.push_back(read_variant(element, defaults));
    const auto [it, inserted] = names.emplace(variants.back().name, variants.size() - 1);
    if (!inserted)
      element.fail("name", "\"" + it->first + "\" names " + section.pointer_of("variants") + "/" +
                               std::to_string(it->second) + " too");
  }
  return variants;
}

// A tree's scale (or a scatter's [lo, hi], `key` of `where`) and the variants it may take =>
// nothing, or the refusal of a scale that grows a species past its range of heights.
void check_species_scales(SceneObject& where, const char* key, double lo, double hi,
                          const std::vector<const ForestVariant*>& variants) {
  double least = 0, most = std::numeric_limits<double>::infinity();  // the scales every variant takes
  const ForestVariant* refused = nullptr;
  double refused_height = 0;
  size_t held = 0;  // variants held to their species' heights
  for (const ForestVariant* v : variants) {
    // A species' heights are its grammar's: a variant that grows a grammar of its own has none.
    if (!v->species || !v->lsystem.library_grammar) continue;
    ++held;
    least = std::max(least, inward(v->species->min_height / v->height, true));
    most = std::min(most, inward(v->species->max_height / v->height, false));
    const double height = (v->height * lo < v->species->min_height ? lo : hi) * v->height;
    if (!refused && (height < v->species->min_height || height > v->species->max_height)) {
      refused = v;
      refused_height = height;
    }
  }
  if (!refused) return;
  const std::string remedy =
      least > most ? "no scale keeps every variant it may draw within its species' heights (give their heights "
                     "ranges that overlap, in /species/height)"
      : held > 1 ? "give a scale from " + number_text(least) + " to " + number_text(most) +
                                  ", which keeps every variant it may draw within its species' heights"
                            : "give a scale from " + number_text(least) + " to " + number_text(most);
  where.fail(key, range_text(*refused->species) + number_text(refused_height) + " m for variant \"" + refused->name +
                      "\" (" + number_text(refused->height) + " m at scale 1): " + remedy);
}

// "0007": index i of a forest of `total` trees, zero-padded to at least 4 digits.
std::string padded_id(size_t i, size_t total) {
  const size_t width = std::max<size_t>(4, std::to_string(total > 0 ? total - 1 : 0).size());
  std::string text = std::to_string(i);
  return std::string(width - std::min(width, text.size()), '0') + text;
}

ForestTree read_listed_tree(SceneObject element, size_t index, size_t total, const std::vector<ForestVariant>& variants,
                            uint64_t scene_seed) {
  ForestTree tree;
  tree.pointer = element.pointer();
  const auto id = element.optional_string("id");
  if (id && !is_file_safe(*id))
    element.fail_expected("id", "an id of 1 to 64 letters, digits, '_', '-' or '.' (not first)");
  tree.id = id ? *id : padded_id(index, total);
  const std::string variant = element.string("variant", variants.front().name);
  const auto found = std::find_if(variants.begin(), variants.end(), [&](const auto& v) { return v.name == variant; });
  if (found == variants.end()) {
    std::string names;
    for (const auto& v : variants) names += (names.empty() ? "\"" : ", \"") + v.name + "\"";
    element.fail("variant", "expected one of the variants' names (" + names + "), got \"" + variant + "\"");
  }
  tree.variant = static_cast<uint32_t>(found - variants.begin());
  tree.position = element.vector3("position", Eigen::Vector3d::Zero(), kGround);
  tree.rotation = element.number("rotation", 0, kTurn);
  tree.scale = element.number("scale", 1, kTreeScale);
  check_species_scales(element, "scale", tree.scale, tree.scale, {&*found});
  RandomStream random{scene_seed ^ 0x7472656573656564ull ^ (uint64_t(index) << 20)};  // "treeseed", by index
  tree.seed = static_cast<uint64_t>(
      element.integer("seed", static_cast<long long>(random.next_u64() & kSeedMask), 0, 1LL << 53));
  return tree;
}

// What /forest/scatter asks for besides its count, read and checked whatever the count (a
// scatter of 0 trees holds valid keys, as one of more does).
struct ScatterSettings {
  ScatterArea area;
  uint64_t seed = 0;
  long long attempts = 0;
  std::array<double, 2> rotation{}, scale{};
};

ScatterSettings read_scatter(SceneObject& scatter, uint64_t scene_seed) {
  if (!scatter.has("min") || !scatter.has("max"))
    scatter.fail(scatter.has("min") ? "max" : "min", "expected the area's corners min and max, each [x, z] in m");
  ScatterSettings settings;
  const auto min = scatter.pair("min", {0, 0}, kGround), max = scatter.pair("max", {0, 0}, kGround);
  settings.area = ScatterArea{{min[0], min[1]}, {max[0], max[1]}};
  if (!(settings.area.min.array() <= settings.area.max.array()).all())
    scatter.fail("max", "expected a corner at or beyond min in x and z");
  settings.seed = static_cast<uint64_t>(scatter.integer("seed", static_cast<long long>(scene_seed), 0, 1LL << 53));
  settings.attempts = scatter.integer("attempts", 1000, 1, 1'000'000);
  settings.rotation = scatter.pair("rotation", {0, 360}, kTurn);
  settings.scale = scatter.pair("scale", {1, 1}, kTreeScale);
  if (settings.rotation[0] > settings.rotation[1]) scatter.fail_expected("rotation", "[lo, hi] degrees with lo <= hi");
  if (settings.scale[0] > settings.scale[1]) scatter.fail_expected("scale", "[lo, hi] with lo <= hi");
  return settings;
}

// Scattered trees after the listed ones: positions by dart throwing, and per tree a variant by
// weight, a rotation, a scale and a seed drawn from the tree's own stream (scatter seed, index),
// so that a change of spacing or area moves trees without changing what they are.
void scatter_trees(const SceneObject& scatter, const ScatterSettings& settings, long long count, Forest& forest) {
  const auto& [area, seed, attempts, rotation, scale] = settings;
  // Only the weights' ratios count: they are drawn from scaled by a power of two (exactly) to
  // a largest of 1 ... 2, so that no sum overflows (1e308 twice) and a subnormal weight is
  // not lost beside 0; a zero weight is never drawn, not even by a sum's round-off.
  double largest = 0;
  size_t last_drawn = 0;
  for (size_t i = 0; i < forest.variants.size(); ++i) {
    largest = std::max(largest, forest.variants[i].weight);
    if (forest.variants[i].weight > 0) last_drawn = i;
  }
  if (!(largest > 0)) scatter.fail("count", "the variants' weights sum to 0: give a variant a weight > 0 to scatter");
  std::vector<double> weight;
  for (const ForestVariant& v : forest.variants) weight.push_back(std::ldexp(v.weight, -std::ilogb(largest)));
  double total_weight = 0;
  for (const double w : weight) total_weight += w;

  std::vector<Eigen::Vector2d> listed;
  for (const ForestTree& tree : forest.trees) listed.emplace_back(tree.position.x(), tree.position.z());
  const auto points = scatter_points(seed, static_cast<size_t>(count), area, forest.spacing, attempts, listed);
  if (points.size() < static_cast<size_t>(count))
    scatter.fail("count", "placed " + std::to_string(points.size()) + " of " + std::to_string(count) +
                              " trees in the area with /forest/spacing " + number_text(forest.spacing) + " m (" +
                              std::to_string(attempts) +
                              " darts each): enlarge the area (min, max), lower the count or the spacing");
  const size_t first = forest.trees.size(), total = first + points.size();
  for (size_t k = 0; k < points.size(); ++k) {
    ForestTree tree;
    tree.pointer = scatter.pointer();
    tree.id = padded_id(first + k, total);
    RandomStream random{(seed * 0x9e3779b97f4a7c15ull) ^ (uint64_t(k) + 0x5ca77e4ull)};  // the tree's stream
    double pick = random.uniform() * total_weight;
    tree.variant = 0;
    while (tree.variant < last_drawn && (pick >= weight[tree.variant] || weight[tree.variant] == 0)) {
      pick -= weight[tree.variant];
      ++tree.variant;
    }
    tree.rotation = rotation[0] + random.uniform() * (rotation[1] - rotation[0]);
    tree.scale = scale[0] + random.uniform() * (scale[1] - scale[0]);
    tree.seed = random.next_u64() & kSeedMask;
    tree.position = Eigen::Vector3d(points[k].x(), 0, points[k].y());
    forest.trees.push_back(std::move(tree));
  }
}

}  // namespace

Forest read_forest(SceneObject section, const ForestDefaults& defaults) {
  Forest forest;
  // Keys with defaults first: adding a key to this object moves its members, and the sections
  // read below keep pointers into them.
  forest.spacing = section.number("spacing", 0, Range::between(0, 1000));
  forest.variants = read_variants(section, defaults);
  std::vector<SceneObject> listed;
  if (section.has("trees")) listed = section.array_of_objects("trees");
  else section.declare("trees");
  long long scatter_count = 0;
  std::optional<SceneObject> scatter;
  if (section.has("scatter")) {
    scatter = section.object("scatter");
    scatter_count = scatter->integer("count", 0, 0, 1'000'000);
  } else {
    section.declare("scatter");
  }
  const size_t total = listed.size() + static_cast<size_t>(scatter_count);
  if (total == 0)
    section.fail("trees", "a forest with no trees: list trees in /forest/trees or give /forest/scatter/count >= 1");

  for (size_t i = 0; i < listed.size(); ++i)
    forest.trees.push_back(read_listed_tree(listed[i], i, total, forest.variants, defaults.seed));
  std::vector<Eigen::Vector2d> ground;
  for (const ForestTree& tree : forest.trees) ground.emplace_back(tree.position.x(), tree.position.z());
  if (const auto pair = closer_than(ground, forest.spacing)) {
    const auto [a, b] = *pair;
    listed[b].fail("position", number_text((ground[a] - ground[b]).norm()) + " m from " + forest.trees[a].pointer +
                                   " on the ground, closer than /forest/spacing = " + number_text(forest.spacing) +
                                   " m: move one of them or lower the spacing");
  }
  if (scatter) {
    const ScatterSettings settings = read_scatter(*scatter, defaults.seed);
    std::vector<const ForestVariant*> drawn;  // the variants a scattered tree may be
    for (const ForestVariant& v : forest.variants)
      if (v.weight > 0) drawn.push_back(&v);
    if (scatter_count > 0) check_species_scales(*scatter, "scale", settings.scale[0], settings.scale[1], drawn);
    if (scatter_count > 0) scatter_trees(*scatter, settings, scatter_count, forest);
  }

  // Ids name files, and a farm's file system may not tell "a" from "A" (macOS, Windows).
  std::unordered_map<std::string, size_t> ids;
  for (size_t i = 0; i < forest.trees.size(); ++i) {
    std::string folded = forest.trees[i].id;
    for (char& c : folded) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    const auto [it, inserted] = ids.emplace(folded, i);
    if (inserted) continue;
    const std::string& other = forest.trees[it->second].id;
    section.fail("trees", (other == forest.trees[i].id ? "two trees have the id \"" + other + "\""
                                                       : "two trees have the ids \"" + other + "\" and \"" +
                                                             forest.trees[i].id + "\", alike but for letter case") +
                              " (" + forest.trees[it->second].pointer + " and " + forest.trees[i].pointer +
                              "): ids name the trees' files, give each its own");
  }
  return forest;
}

}  // namespace treeanim
