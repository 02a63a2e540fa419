// cuspy contour files read as curves for curveX/curveY/curveZ/curveGAL (CPFG manual 5.5).
#include "lsystem/view_curve.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <string>

#include "common/errors.h"
#include "common/read_text_file.h"

namespace treeanim {

namespace {

constexpr int kMaxPoints = 100'000;  // control points of one curve, multiplicities included

[[noreturn]] void fail(const std::filesystem::path& path, size_t line, const std::string& message) {
  throw InputError(path.string() + ":" + std::to_string(line + 1) + ":1: " + message);
}

// Uniform cubic B-spline through control (at least 4 points), parameter t in [0, 1] spread
// over its control.size() - 3 segments.
std::array<double, 3> spline_point(const std::vector<std::array<double, 3>>& control, double t) {
  const auto segments = static_cast<double>(control.size() - 3);
  const double x = std::clamp(t, 0.0, 1.0) * segments;
  const size_t first = std::min(static_cast<size_t>(x), control.size() - 4);
  const double u = x - static_cast<double>(first);
  const double weights[4] = {(1 - u) * (1 - u) * (1 - u) / 6, (3 * u * u * u - 6 * u * u + 4) / 6,
                             (-3 * u * u * u + 3 * u * u + 3 * u + 1) / 6, u * u * u / 6};
  std::array<double, 3> p{0, 0, 0};
  for (size_t k = 0; k < 4; ++k)
    for (size_t a = 0; a < 3; ++a) p[a] += weights[k] * control[first + k][a];
  return p;
}

}  // namespace

std::array<double, 3> ViewCurve::at(double arc_fraction) const {
  const double s = std::clamp(arc_fraction, 0.0, 1.0);
  size_t lo = 0, hi = arc.size() - 1;
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    if (arc[mid] > s) hi = mid;
    else lo = mid;
  }
  const double span = arc[hi] - arc[lo];
  const double k = static_cast<double>(lo) + (span > 0 ? (s - arc[lo]) / span : 0.0);
  return spline_point(control, k / static_cast<double>(arc.size() - 1));
}

ViewCurve read_view_curve(const std::filesystem::path& path, int samples) {
  std::string text, reason;
  if (!read_text_file(path, text, reason)) throw InputError(path.string() + ": cannot read the curve file (" + reason + ")");
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);

  ViewCurve curve;
  std::string type = "bspline";
  int expected = -1, dimension = 2;  // points announced by "points:", values on a point's line
  size_t points_line = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line.compare(first, 2, "//") == 0) continue;
    const size_t colon = line.find(':');
    std::istringstream values(colon == std::string::npos ? line : line.substr(colon + 1));
    if (colon != std::string::npos) {
      const std::string key = line.substr(first, colon - first);
      if (key == "points") {
        if (expected >= 0) fail(path, i, "expected one 'points:' (curves nested in points are not supported)");
        if (!(values >> expected) || expected < 1) fail(path, i, "expected a number of points after 'points:'");
        points_line = i;
        dimension = 2;
      } else if (key == "dimension" || key == "dim") {
        if (!(values >> dimension) || dimension < 2 || dimension > 4) fail(path, i, "expected a dimension 2, 3 or 4");
      } else if (key == "type") {
        values >> type;
      }
      continue;  // version, contact, end, heading, up, size, range: the curve's placement in cuspy
    }
    if (expected < 0) fail(path, i, "expected 'points: n' before the points");
    double v[4] = {0, 0, 0, 1};
    for (int a = 0; a < dimension; ++a)
      if (!(values >> v[a]) || !std::isfinite(v[a])) fail(path, i, "expected " + std::to_string(dimension) + " numbers on a point's line");
    const double multiplicity = std::trunc(v[3]);
    if (multiplicity < 0 || curve.control.size() + static_cast<size_t>(multiplicity) > kMaxPoints)
      fail(path, i, "expected a multiplicity 0 ... " + std::to_string(kMaxPoints) + " (the 4th number)");
    if (expected == 0) fail(path, i, "more points than 'points:' announces");
    curve.control.insert(curve.control.end(), static_cast<size_t>(multiplicity), {v[0], v[1], v[2]});
    --expected;
  }
  if (expected > 0) fail(path, points_line, "fewer points than 'points:' announces");
  if (type == "bspline-closed") {
    for (size_t k = 0; k < 3 && k < curve.control.size(); ++k) curve.control.push_back(curve.control[k]);
  } else if (type == "bspline-phantom" && curve.control.size() >= 2) {
    const auto phantom = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
      return std::array<double, 3>{2 * a[0] - b[0], 2 * a[1] - b[1], 2 * a[2] - b[2]};
    };
    const size_t n = curve.control.size();
    const std::array<double, 3> front = phantom(curve.control[0], curve.control[1]);
    curve.control.push_back(phantom(curve.control[n - 1], curve.control[n - 2]));
    curve.control.insert(curve.control.begin(), front);
  } else if (type != "bspline") {
    fail(path, 0, "curve type '" + type + "' is not supported (expected bspline, bspline-closed or bspline-phantom)");
  }
  if (curve.control.size() < 4) fail(path, points_line, "expected at least 4 control points (multiplicities included)");

  const int count = std::max(samples, 2);
  curve.arc.assign(static_cast<size_t>(count), 0.0);
  std::array<double, 3> previous = spline_point(curve.control, 0.0);
  for (int k = 1; k < count; ++k) {
    const std::array<double, 3> p = spline_point(curve.control, static_cast<double>(k) / (count - 1));
    curve.length += std::hypot(p[0] - previous[0], p[1] - previous[1], p[2] - previous[2]);
    curve.arc[static_cast<size_t>(k)] = curve.length;
    previous = p;
  }
  if (curve.length > 0)
    for (double& a : curve.arc) a /= curve.length;
  return curve;
}

}  // namespace treeanim
