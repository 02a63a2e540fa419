#pragma once
// A cpfg view file's curve ("curve: file.con [samples]", a cuspy contour file): the functions
// curveX, curveY, curveZ and curveGAL read it by arc length (CPFG manual 5.5).
#include <array>
#include <filesystem>
#include <vector>

namespace treeanim {

struct ViewCurve {
  std::vector<std::array<double, 3>> control;  // (points) uniform cubic B-spline control points, multiplicities expanded
  std::vector<double> arc;                     // (samples) arc length to parameter k / (samples - 1), over the total
  double length = 0.0;                         // arc length of the polyline through the samples (curveGAL)

  // arc length over the total (clamped to [0, 1]) => the point there: the parameter is
  // interpolated between the samples, then the spline evaluated (as cpfg does).
  std::array<double, 3> at(double arc_fraction) const;
};

// path (a .con file), samples (cpfg's default 100) => its curve. Types "bspline",
// "bspline-closed" and "bspline-phantom"; others are refused. Throws InputError
// "file:line:col: message".
ViewCurve read_view_curve(const std::filesystem::path& path, int samples);

}  // namespace treeanim
