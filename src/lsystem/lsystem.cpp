#include "lsystem/lsystem.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "common/direction.h"
#include "common/errors.h"
#include "common/json_text.h"
#include "common/read_text_file.h"

namespace treeanim {

namespace {

std::string read_file(const std::filesystem::path& path) {
  std::string text, reason;
  if (!read_text_file(path, text, reason))
    throw InputError(path.string() + ": cannot read the grammar file (" + reason + ")");
  return text;
}

// A scene define must replace a #define of the file: otherwise it is a typo that would
// silently change nothing.
void check_overrides(const LsystemOptions& options, const Grammar& grammar, const std::string& source) {
  for (const auto& [name, value] : options.defines) {
    if (std::find(grammar.file_defines.begin(), grammar.file_defines.end(), name) != grammar.file_defines.end())
      continue;
    if (std::find(grammar.file_macros.begin(), grammar.file_macros.end(), name) != grammar.file_macros.end())
      throw InputError(options.inline_name("/defines/" + name) + ": the grammar " + source + " defines '" + name +
                       "' as a macro with arguments ('#define " + name + "(...)'), which no number replaces: only a "
                       "constant #define takes the scene's value");
    std::string known;
    for (const std::string& d : grammar.file_defines) known += (known.empty() ? "" : ", ") + d;
    throw InputError(options.inline_name("/defines/" + name) + ": the grammar " + source + " has no '#define " +
                     name + "' (it defines: " +
                     (known.empty() ? "nothing" : known) + ")");
  }
}

// A view file's surface => its leaf shape, with quads per patch from the scene, else the view
// line, else the file's PRECISION, else cpfg's default 5.
LeafShape view_surface_shape(const ViewSurface& v, std::optional<int> scene_precision) {
  constexpr int kDefaultQuads = 5;
  const std::array<int, 2> quads = scene_precision ? std::array<int, 2>{*scene_precision, *scene_precision}
                                                   : v.precision.value_or(v.surface.precision.value_or(std::array<int, 2>{kDefaultQuads, kDefaultQuads}));
  LeafShape shape = surface_shape(v.surface, v.id, v.scale, quads[0], quads[1]);
  // No area: no triangle left, or only slivers along a line (a leaf without drag or mass).
  double area = 0, extent = 0;
  for (size_t t = 0; t < shape.triangles.size(); t += 3) {
    const Eigen::Vector3d& a = shape.points[shape.triangles[t]];
    area += 0.5 * (shape.points[shape.triangles[t + 1]] - a).cross(shape.points[shape.triangles[t + 2]] - a).norm();
  }
  for (const Eigen::Vector3d& p : shape.points) extent = std::max(extent, (p - shape.points[0]).cwiseAbs().maxCoeff());
  if (!(area > 1e-9 * extent * extent))
    throw InputError(v.where + ": the surface '" + std::string(1, v.id) + "' has no area (every patch collapses to a line or a point)");
  return shape;
}

// The tropisms of the grammar and the view file, and the scene's lsystem.tropism and
// lsystem.tropism_elasticity in place of the first of them: the view file's first "tropism:"
// line (its T: direction, keeping its intensity, and its E:), else its older "tropism
// direction:"/"initial elasticity:" when it gives either, else the grammar's "tropism:".
void set_tropisms(const LsystemOptions& options, const Grammar& grammar, const ViewSettings& view, TurtleSettings& turtle) {
  turtle.movements = view.movements;
  turtle.old_tropism = view.old_tropism.value_or(turtle.old_tropism);
  turtle.initial_elasticity = view.initial_elasticity.value_or(0.0);
  turtle.elasticity_increment = view.elasticity_increment.value_or(0.0);
  if (grammar.tropism) {
    turtle.tropism = *grammar.tropism;
    turtle.tropism_elasticity = grammar.tropism_elasticity;
  }
  const auto first = std::find_if(turtle.movements.begin(), turtle.movements.end(), [](const Movement& m) { return !m.torque; });
  if (first != turtle.movements.end()) {
    if (options.tropism) first->direction = *unit_direction(*options.tropism) * first->direction.norm();
    if (options.tropism_elasticity) first->elasticity = *options.tropism_elasticity;
  } else if (view.old_tropism || view.initial_elasticity) {
    if (options.tropism) turtle.old_tropism = *unit_direction(*options.tropism);
    if (options.tropism_elasticity) turtle.initial_elasticity = *options.tropism_elasticity;
  } else {
    if (options.tropism) turtle.tropism = *options.tropism;
    if (options.tropism_elasticity) turtle.tropism_elasticity = *options.tropism_elasticity;
  }
}

}  // namespace

ViewSettings load_view(const LsystemOptions& options) {
  return options.view ? read_view_file(*options.view) : ViewSettings{};
}

std::string LsystemOptions::inline_name(const std::string& suffix) const {
  const std::string at = pointer + suffix;
  const std::string* source = &scene_name;
  for (const auto& [target, argument] : set_by)
    if (pointer_within(at, target)) source = &argument;
  return source->empty() ? at : *source + ": " + at;
}

std::string grammar_name(const LsystemOptions& options) {
  return options.grammar ? options.grammar->string()
                         : options.library_grammar ? options.library_grammar->name : options.inline_name();
}

Grammar load_grammar(const LsystemOptions& options, const ViewSettings& view) {
  if (options.grammar || options.library_grammar) {
    const GrammarText text = options.grammar ? GrammarText{options.grammar->string(), read_file(*options.grammar), false}
                                             : *options.library_grammar;
    Grammar grammar = parse_grammar({text}, options.defines, std::nullopt, view.functions, view.curves);
    check_overrides(options, grammar, text.name);
    return grammar;
  }
  std::vector<GrammarText> texts;
  for (size_t i = 0; i < options.productions.size(); ++i)
    texts.push_back({options.inline_name("/productions/" + std::to_string(i)), options.productions[i], true});
  return parse_grammar(texts, options.defines, GrammarText{options.inline_name("/axiom"), options.axiom, true});
}

std::vector<std::filesystem::path> grammar_input_files(const LsystemOptions& options) {
  if (!options.grammar && !options.view) return {};
  ViewSettings view = load_view(options);
  std::vector<std::filesystem::path> files = std::move(view.files);
  if (options.grammar) {
    const Grammar grammar = load_grammar(options, view);
    files.insert(files.end(), grammar.sources.begin() + 1, grammar.sources.end());  // the first is the grammar file
    files.insert(files.end(), grammar.data_paths.begin(), grammar.data_paths.end());
  }
  return files;
}

DerivationSettings derivation_settings(const LsystemOptions& options, const Grammar& grammar) {
  DerivationSettings settings;
  if (options.iterations) settings.iterations = *options.iterations;
  else if (grammar.derivation_length) settings.iterations = *grammar.derivation_length;
  else
    throw InputError(grammar.sources.at(0) + ": the grammar has no 'derivation length:'; give the number of steps as " +
                     options.pointer + "/iterations");
  // Seed 0 in the grammar leaves the scene seed as it is.
  settings.seed = options.seed ^ (grammar.seed * 0x9e3779b97f4a7c15ULL);
  settings.max_modules = options.max_modules;
  return settings;
}

TurtleSettings turtle_settings(const LsystemOptions& options, const Grammar& grammar, const ViewSettings& view) {
  TurtleSettings turtle;
  turtle.step = options.step;
  turtle.angle_degrees = options.angle.value_or(view.angle.value_or(grammar.angle.value_or(turtle.angle_degrees)));
  turtle.width_factor = options.width_factor.value_or(grammar.width_factor.value_or(turtle.width_factor));
  turtle.initial_width = view.initial_width.value_or(turtle.initial_width);
  turtle.calls = grammar.calls;
  if (options.view) turtle.width_increment = view.width_increment.value_or(1.0);
  set_tropisms(options, grammar, view, turtle);
  turtle.initial_scale = view.initial_scale.value_or(1.0);
  turtle.scale_multiplier = view.scale_multiplier.value_or(1.0);
  for (const ViewSurface& v : view.surfaces) turtle.surfaces.push_back(view_surface_shape(v, options.surface_precision));
  return turtle;
}

bool seed_shapes_growth(const LsystemOptions& options) {
  const Grammar grammar = load_grammar(options, load_view(options));
  for (const Instruction& instruction : grammar.program.code)
    if (instruction.op == Op::kRan || instruction.op == Op::kNran || instruction.op == Op::kBran ||
        instruction.op == Op::kBiran)
      return true;
  for (const Lsystem& lsystem : grammar.lsystems)
    for (const RuleSet* set : {&lsystem.productions, &lsystem.decomposition, &lsystem.homomorphism})
      for (const Rule& rule : set->rules)
        if (rule.probability.present()) return true;
  return false;
}

Skeleton grow_skeleton(const LsystemOptions& options, GrowthStats* stats,
                       const std::function<void(int step, int steps, size_t modules)>& stepped) {
  const ViewSettings view = load_view(options);
  const Grammar grammar = load_grammar(options, view);
  const DerivationSettings settings = derivation_settings(options, grammar);
  const TurtleSettings turtle = turtle_settings(options, grammar, view);
  std::vector<double> variables;  // as the derivation leaves them, for the homomorphism (CPFG manual 4.3.1)
  DerivationStepped step_done;
  if (stepped) step_done = [&](int step, size_t modules) { stepped(step, settings.iterations, modules); };
  const ModuleString word = derive(grammar, settings, turtle, &variables, step_done);
  if (stats) {
    stats->modules = word.size();
    stats->iterations = settings.iterations;
  }
  return interpret(apply_homomorphism(grammar, word, settings, &variables), turtle);
}

}  // namespace treeanim
