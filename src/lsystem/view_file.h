#pragma once
// A cpfg view file (.v, CPFG manual 8.1): the settings that shape the tree. Rendering settings
// (viewpoint, lights, colours, render mode...) are read past and have no effect.
#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "lsystem/expression.h"
#include "lsystem/surface_file.h"
#include "lsystem/tropism.h"

namespace treeanim {

// "surface: id file.s scale [i j] [texture]" (CPFG manual 8.1.5) with its file read.
struct ViewSurface {
  char id = 0;                                  // the letter of ~id
  BezierSurface surface;                        // the .s file, found beside the view file
  double scale = 1.0;                           // the surface's SIZE is drawn this long (scene units)
  std::optional<std::array<int, 2>> precision;  // "i j": quads per patch along s, t (clamped to 1 ... 10)
  std::string where;                            // "view.v:7:1", to place errors about this surface
};

struct ViewSettings {
  std::optional<double> angle;                // "angle increment: a" or 360 / "angle factor: n"
  std::optional<double> initial_width;        // "initial line width: w" (not in pixels)
  std::optional<double> width_increment;      // "line width increment: d": '#' adds, '!' subtracts
  std::vector<Movement> movements;            // "tropism:" and "torque:" lines, in order (ids 1, 2, ...)
  std::optional<Eigen::Vector3d> old_tropism; // "tropism direction: x,y,z", made unit (8.1.10); 0,0,0: none
  std::optional<double> initial_elasticity;   // "initial elasticity: e" of that tropism
  std::optional<double> elasticity_increment; // "elasticity increment: d": what '_' adds
  std::optional<double> initial_scale;        // "initial scale: s" (0 reads as 1, as in cpfg)
  std::optional<double> scale_multiplier;     // "scale multiplier: m" of @Di/@Dd (0 reads as 1)
  std::vector<ViewSurface> surfaces;          // "surface:" lines whose file exists, in order: drawn by ~id as leaves
  std::vector<SampledFunction> functions;     // "function: f.func n" / "function set: s.fset", in order
  std::vector<ViewCurve> curves;              // "curve: c.con [samples]", in order (curveX ... curveGAL)
  // Every file its lines name (surfaces, curves, functions), read or, for a surface, absent
  // (cpfg then leaves it out): what else a bake's key holds (grammar_input_files).
  std::vector<std::filesystem::path> files;
};

// path => settings; files it names are found beside it. Throws InputError "file:line:col: message".
ViewSettings read_view_file(const std::filesystem::path& path);

// The text of a funcedit function ("fver 1 1" format, or the older one from "range:") => its
// "name:" and its B-spline sampled at equally spaced x in [0, 1]. `name` (the file) places
// errors. *pos moves past the function.
SampledFunction parse_function(const std::string& name, const std::vector<std::string>& lines, size_t* pos);

}  // namespace treeanim
