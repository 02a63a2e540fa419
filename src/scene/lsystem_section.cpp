#include "scene/lsystem_section.h"

#include <cctype>

#include "common/direction.h"

namespace treeanim {

namespace {

bool is_name(const std::string& text) {
  if (text.empty() || !(std::isalpha(static_cast<unsigned char>(text[0])) || text[0] == '_')) return false;
  for (char c : text)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

// /lsystem/productions: an array of strings (one rule or directive each).
std::vector<std::string> read_productions(SceneObject& section) {
  std::vector<std::string> out;
  const Json* value = section.raw("productions");
  if (!value) return out;
  if (!value->is_array()) section.fail_expected("productions", "an array of strings (one production each)");
  for (size_t i = 0; i < value->size(); ++i) {
    const Json& element = value->at(i);
    if (!element.is_string()) section.fail_element("productions", i, "a string (one production)");
    out.push_back(element.get<std::string>());
  }
  return out;
}

// /lsystem/defines: {"name": number}; each value is range-checked as /lsystem/defines/name.
std::vector<std::pair<std::string, double>> read_defines(SceneObject& section) {
  std::vector<std::pair<std::string, double>> out;
  const Json* value = section.raw("defines");
  if (!value) return out;
  if (!value->is_object()) section.fail_expected("defines", "an object of name: number");
  std::vector<std::string> names;
  for (auto it = value->begin(); it != value->end(); ++it) names.push_back(it.key());
  SceneObject defines = section.object("defines");
  for (const std::string& name : names) {
    if (!is_name(name)) defines.fail(name, "expected a name of letters, digits and '_' (not starting with a digit)");
    // null takes the default, as for any key: the grammar's own #define, or none
    if (const std::optional<double> number = defines.optional_number(name)) out.emplace_back(name, *number);
  }
  return out;
}

}  // namespace

LsystemOptions read_lsystem_options(SceneObject section, uint64_t scene_seed, const GrammarText* species_grammar) {
  LsystemOptions options;
  options.scene_name = section.source_name();
  options.pointer = section.pointer();
  options.set_by = section.overrides();
  options.grammar = section.optional_path("grammar");
  const std::optional<std::string> axiom = section.optional_string("axiom");
  options.productions = read_productions(section);
  if (options.grammar && axiom)
    section.fail("axiom", "give either a grammar file (/lsystem/grammar) or an inline grammar (/lsystem/axiom), not both");
  if (!options.grammar && !axiom && species_grammar) options.library_grammar = *species_grammar;
  else if (!options.grammar && !axiom)
    section.fail("grammar", "expected a grammar file, or an inline grammar as /lsystem/axiom and /lsystem/productions "
                            "(or a /species, which brings its own)");
  if (options.grammar && !options.productions.empty())
    section.fail("productions", "inline productions go with /lsystem/axiom, not with a grammar file (/lsystem/grammar)");
  if (options.library_grammar && !options.productions.empty())
    section.fail("productions", "inline productions go with /lsystem/axiom; the species' grammar has its own (give "
                                "an axiom to grow an inline grammar instead)");
  if (axiom) options.axiom = *axiom;
  options.view = section.optional_path("view");
  if (options.view && !options.grammar) section.fail("view", "a view file goes with a grammar file (/lsystem/grammar)");
  options.defines = read_defines(section);
  if (auto n = section.optional_integer("iterations", 0, 100000)) options.iterations = static_cast<int>(*n);
  options.seed = static_cast<uint64_t>(section.integer("seed", static_cast<long long>(scene_seed), 0, 1LL << 53));
  options.step = section.number("step", 1.0, Range::positive());
  options.angle = section.optional_number("angle", Range::between(-360, 360));
  options.max_modules = static_cast<size_t>(section.integer("max_modules", 20'000'000, 1, 1LL << 29));
  options.width_factor = section.optional_number("width_factor", Range::positive());
  options.tropism = section.optional_vector3("tropism");
  if (options.tropism && (!unit_direction(*options.tropism) || !(options.tropism->norm() <= kMaxTropism)))
    section.fail_expected("tropism", "a non-zero direction [x, y, z] at most 1e6 long");
  options.tropism_elasticity = section.optional_number("tropism_elasticity", Range::between(-kMaxTropism, kMaxTropism));
  if (auto n = section.optional_integer("surface_precision", 1, 10)) options.surface_precision = static_cast<int>(*n);
  if (options.surface_precision && !options.view)
    section.fail("surface_precision", "the precision of surfaces goes with a view file that names them (/lsystem/view)");
  return options;
}

}  // namespace treeanim
