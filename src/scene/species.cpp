#include "scene/species.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <stdexcept>

#include "common/did_you_mean.h"
#include "common/message_text.h"
#include "scene/sim_sections.h"
#include "scene/tree_section.h"
#include "species_library.h"

namespace treeanim {

namespace {

constexpr const char* kTableName = "grammars/species/species.json";

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return text;
}

// The table is part of the build: a defect in it is the program's, not the user's (exit 3).
[[noreturn]] void table_defect(const std::string& message) {
  throw std::logic_error(std::string(kTableName) + ": " + message);
}

std::string table_string(const Json& entry, const std::string& key) {
  if (!entry.contains(key) || !entry[key].is_string() || entry[key].get<std::string>().empty())
    table_defect("an entry has no string \"" + key + "\"");
  return entry[key].get<std::string>();
}

GrammarText embedded_grammar(const std::string& file) {
  for (const EmbeddedFile& grammar : kSpeciesGrammars)
    if (file == grammar.name) return {"grammars/species/" + file, grammar.text, false};
  table_defect("no grammar file grammars/species/" + file);
}

// An entry's section (its "tree" or "hsm") as a scene of its own, read by the scene's readers.
template <typename Read>
auto read_preset(const Species& species, const Json& entry, const std::string& key, Read read) {
  Json document = Json::object();
  document[key] = entry.contains(key) ? entry[key] : Json::object();
  SceneReader reader(document, "", std::string(kTableName) + " (" + species.name + ")");
  auto options = read(reader.root().object(key));
  reader.check_unknown_keys();
  return options;
}

Species read_entry(const Json& entry) {
  Species s;
  s.name = table_string(entry, "name");
  s.common = table_string(entry, "common");
  s.latin = table_string(entry, "latin");
  s.habit = table_string(entry, "habit");
  const Json& height = entry.value("height", Json::object());
  s.default_height = height.value("default", 0.0);
  s.min_height = height.value("min", 0.0);
  s.max_height = height.value("max", 0.0);
  if (!(0 < s.min_height && s.min_height <= s.default_height && s.default_height <= s.max_height))
    table_defect(s.name + ": expected 0 < height.min <= height.default <= height.max");
  s.sway_frequency = entry.value("sway_frequency_hz", 0.0);
  if (!(s.sway_frequency > 0)) table_defect(s.name + ": expected its measured sway_frequency_hz > 0");
  s.grammar = embedded_grammar(table_string(entry, "grammar"));
  s.tree = read_preset(s, entry, "tree", [](SceneObject section) { return read_tree_options(section); });
  s.hsm = entry.value("hsm", Json::object());
  (void)read_preset(s, entry, "hsm", [](SceneObject section) { return read_hsm_options(section); });
  s.sources = entry.value("sources", Json::object());
  return s;
}

std::vector<Species> parse_library() {
  const Json table = parse_json_text(kSpeciesTable, kTableName);
  if (!table.contains("species") || !table["species"].is_array()) table_defect("expected {\"species\": [...]}");
  std::vector<Species> library;
  for (const Json& entry : table["species"]) library.push_back(read_entry(entry));
  return library;
}

// The species a mistyped or partial name most likely means: one whose name or common name holds
// it, else the nearest by edit distance.
const Species& closest_species(const std::string& word) {
  const std::vector<Species>& library = species_library();
  const std::string key = lower(word);
  for (const Species& s : library)
    if (!key.empty() && (s.name.find(key) != std::string::npos || lower(s.common).find(key) != std::string::npos))
      return s;
  return *std::min_element(library.begin(), library.end(), [&](const Species& a, const Species& b) {
    return edit_distance(key, a.name) < edit_distance(key, b.name);
  });
}

[[noreturn]] void fail_unknown(SceneObject& section, const std::string& key, const std::string& name) {
  std::string names;
  for (const Species& s : species_library()) names += (names.empty() ? "" : ", ") + s.name;
  const std::string near = name.empty() ? "" : " (did you mean " + closest_species(name).name + "?)";
  section.fail(key, "no species \"" + name + "\"" + near + "; the library has " + names +
                        " (treeanim species lists them)");
}

const Species* find_species(const std::string& name) {
  for (const Species& s : species_library())
    if (s.name == name) return &s;
  return nullptr;
}

// `parent`'s /tree/scale when it is a number > 0 (anything else is left to the tree's reader,
// which refuses it).
std::optional<double> given_scale(SceneObject& parent) {
  const Json* tree = parent.raw("tree");
  if (!tree || !tree->is_object()) return std::nullopt;
  const auto scale = tree->find("scale");
  if (scale == tree->end() || !scale->is_number()) return std::nullopt;
  const double value = scale->get<double>();
  return value > 0 && std::isfinite(value) ? std::optional<double>(value) : std::nullopt;
}

// A height => whether the species grows to it in the field (its range).
bool outside_range(const Species& s, double height) { return height < s.min_height || height > s.max_height; }

}  // namespace

std::string range_text(const Species& s) {
  return s.common + " (" + s.name + ") grows from " + number_text(s.min_height) + " to " + number_text(s.max_height) + " m, got ";
}

double inward(double bound, bool lower) {
  if (bound == 0 || !std::isfinite(bound)) return bound;
  // The bound as a message prints it, when that is inside the range (a scale of exactly 1).
  const double shown = std::strtod(number_text(bound).c_str(), nullptr);
  if (lower ? shown >= bound : shown <= bound) return shown;
  const double unit = std::pow(10.0, std::floor(std::log10(std::fabs(bound))) - 5);
  return (lower ? std::ceil(bound / unit) : std::floor(bound / unit)) * unit;
}

const std::vector<Species>& species_library() {
  static const std::vector<Species> library = parse_library();
  return library;
}

std::optional<SpeciesChoice> read_species(SceneObject& parent) {
  const Json* value = parent.raw("species");
  if (!value) return std::nullopt;
  SpeciesChoice choice;
  // A /tree/scale without a height sets the size as the height does: the height it grows the
  // preset to (its scale is the default height's), which the resolved scene records.
  const std::optional<double> scale = given_scale(parent);
  auto scaled_height = [&](const Species& s) {
    const double height = s.default_height * (*scale / s.tree.scale);
    if (outside_range(s, height))
      parent.object("tree").fail("scale", range_text(s) + number_text(height) + " m from a scale of " + number_text(*scale) +
                                              ": give a scale from " +
                                              number_text(inward(s.tree.scale * s.min_height / s.default_height, true)) +
                                              " to " +
                                              number_text(inward(s.tree.scale * s.max_height / s.default_height, false)) +
                                              ", or the species' height");
    return height;
  };
  if (value->is_string()) {
    choice.species = find_species(value->get<std::string>());
    if (!choice.species) fail_unknown(parent, "species", value->get<std::string>());
    choice.height = scale ? scaled_height(*choice.species) : choice.species->default_height;
    return choice;
  }
  if (!value->is_object())
    parent.fail_expected("species", "a species' name, or {\"name\": NAME, \"height\": METRES}");
  SceneObject section = parent.object("species");
  const std::optional<std::string> name = section.optional_string("name");
  if (!name) section.fail_expected("name", "a species' name (treeanim species lists them)");
  choice.species = find_species(*name);
  if (!choice.species) fail_unknown(section, "name", *name);
  const Species& s = *choice.species;
  choice.height_given = section.has("height");
  choice.height = section.number("height", scale && !choice.height_given ? scaled_height(s) : s.default_height,
                                 Range::positive());
  if (outside_range(s, choice.height)) section.fail("height", range_text(s) + number_text(choice.height));
  return choice;
}

void check_species_scale(const SpeciesChoice& choice, SceneObject tree) {
  const Json* scale = tree.raw("scale");
  // A resolved scene records both; its height came from the scale or the scale from it, each
  // to the round-off of the other's quotient.
  const double grown = species_tree(choice).scale;
  if (choice.height_given && scale &&
      !(scale->is_number() && std::abs(scale->get<double>() - grown) <= 1e-12 * grown))
    tree.fail("scale", "the species' height of " + number_text(choice.height) + " m grows it at a scale of " +
                           number_text(grown) + ": give the height or the scale, or both as they agree (a resolved "
                           "scene records both)");
}

TreeOptions species_tree(const SpeciesChoice& choice) {
  return scaled_tree_options(choice.species->tree, choice.factor());
}

HsmOptions species_hsm(const SpeciesChoice& choice, const HsmOptions& base) {
  Json document = Json{{"hsm", choice.species->hsm}};
  SceneReader reader(document, "", std::string(kTableName) + " (" + choice.species->name + ")");
  return read_hsm_options(reader.root().object("hsm"), base);
}

}  // namespace treeanim
