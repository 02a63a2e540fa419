#pragma once
// A cpfg view file (.v, CPFG manual 8.1): the settings that shape the tree. Rendering settings
// (viewpoint, lights, colours, render mode...) are read past and have no effect.
#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "lsystem/expression.h"

namespace treeanim {

struct ViewSettings {
  std::optional<double> angle;                // "angle increment: a" or 360 / "angle factor: n"
  std::optional<double> initial_width;        // "initial line width: w" (not in pixels)
  std::optional<double> width_increment;      // "line width increment: d": '#' adds, '!' subtracts
  std::optional<Eigen::Vector3d> tropism;     // "tropism: T: x,y,z ..."
  std::optional<double> tropism_elasticity;   // "... E: e" or "initial elasticity: e"
  std::vector<char> surfaces;                 // "surface: id file.s ...": ids drawn by ~id as leaves
  std::vector<SampledFunction> functions;     // "function: f.func n" / "function set: s.fset", in order
  std::vector<ViewCurve> curves;              // "curve: c.con [samples]", in order (curveX ... curveGAL)
};

// path => settings; files it names are found beside it. Throws InputError "file:line:col: message".
ViewSettings read_view_file(const std::filesystem::path& path);

// The text of a funcedit function ("fver 1 1" format, or the older one from "range:") => its
// "name:" and its B-spline sampled at equally spaced x in [0, 1]. `name` (the file) places
// errors. *pos moves past the function.
SampledFunction parse_function(const std::string& name, const std::vector<std::string>& lines, size_t* pos);

}  // namespace treeanim
