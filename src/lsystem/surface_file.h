#pragma once
// A cpfg surface file (.s, written by bezieredit and stedit; CPFG manual 6.7.1 and 8.1.5):
// bicubic Bézier patches with the point and frame by which the turtle places them.
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <optional>
#include <vector>

namespace treeanim {

struct BezierSurface {
  std::optional<std::array<int, 2>> precision;  // "PRECISION S: s T: t": quads per patch along s (rows), t (columns)
  Eigen::Vector3d contact{0, 0, 0};             // file units: the point placed at the turtle's position
  Eigen::Vector3d end{0, 0, 0};                 // file units: where the turtle stands after drawing
  Eigen::Vector3d heading{0, 1, 0};             // unit: the direction drawn along the turtle's H
  Eigen::Vector3d up{0, 0, 1};                  // unit, perpendicular to heading: drawn along the turtle's U
  double size = 1.0;                            // file units drawn as the view line's scale (> 0)
  std::vector<std::array<Eigen::Vector3d, 16>> patches;  // (K) control points, row-major 4 x 4 (row = s), file units
};

// path => its surface. Throws InputError "file:line:col: expected ..." at the first thing that
// is not in the format.
BezierSurface read_surface_file(const std::filesystem::path& path);

}  // namespace treeanim
