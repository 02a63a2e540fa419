#pragma once
// Scene section /lsystem (docs/scene.md), read by scene/ (src/scene/lsystem_section.h).
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace treeanim {

// One text of a grammar: a whole file, or one inline rule (single_line: reported as "name, column N").
struct GrammarText {
  std::string name;
  std::string text;
  bool single_line = false;
};

// The longest tropism direction and the largest elasticity, in a grammar's "tropism:" or the
// scene: the turn of e |H x T| rad a segment stays finite (ABOP's e is below 1, T a unit vector).
inline constexpr double kMaxTropism = 1e6;

struct LsystemOptions {
  std::optional<std::filesystem::path> grammar;  // grammar file, resolved against the scene folder
  std::optional<GrammarText> library_grammar;    // a species' grammar (in memory), when no file or inline one is given
  std::optional<std::filesystem::path> view;     // cpfg view file (.v), with a grammar file
  std::string axiom;                             // inline grammar (when no file)
  std::vector<std::string> productions;          // inline productions, one rule per string
  std::vector<std::pair<std::string, double>> defines;  // override #define values
  std::optional<int> iterations;                 // overrides "derivation length:"
  uint64_t seed = 1;                             // stochastic productions, ran(), nran()
  double step = 1.0;                             // length of an F without parameter (scene units)
  std::optional<double> angle;                   // overrides "angle:" (degrees)
  size_t max_modules = 20'000'000;               // derivation stops with an error beyond this
  std::optional<double> width_factor;            // overrides "width factor:" ('!' without a parameter)
  std::optional<Eigen::Vector3d> tropism;        // overrides T of "tropism:"
  std::optional<double> tropism_elasticity;      // overrides e of "tropism:"
  std::optional<int> surface_precision;          // quads per patch along s and t of every view-file surface (1 ... 10)
  std::string scene_name;                        // the scene file that holds the section ("" when none)
  std::string pointer = "/lsystem";              // the section's JSON pointer in it
  std::vector<std::pair<std::string, std::string>> set_by;  // pointer => the --set argument that gave it
  // What messages call the section's value at `suffix` ("", "/axiom", "/productions/3"): "scene.json:
  // /lsystem/axiom", or "--set 'lsystem.axiom=F': /lsystem/axiom" for a value given on the command line.
  std::string inline_name(const std::string& suffix = "") const;
};

}  // namespace treeanim
