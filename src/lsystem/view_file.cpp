// cpfg view files and funcedit functions (CPFG manual 8.1, 8.1.6).
#include "lsystem/view_file.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <sstream>

#include "common/direction.h"
#include "common/errors.h"
#include "common/read_text_file.h"
#include "lsystem/data_file.h"

namespace treeanim {

namespace {

constexpr int kSamples = 1024;  // x samples of a function (cpfg samples its own at "samples:")

std::vector<std::string> read_lines(const std::filesystem::path& path, const std::string& what) {
  std::string text, reason;
  if (!read_text_file(path, text, reason))
    throw InputError(path.string() + ": cannot read the " + what + " (" + reason + ")");
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);  // CRLF read as LF already
  return lines;
}

[[noreturn]] void fail(const std::string& name, size_t line, const std::string& message) {
  throw InputError(name + ":" + std::to_string(line + 1) + ":1: " + message);
}

// "key: rest" with the key in lower case; false when the line has no ':'.
bool split_key(const std::string& line, std::string* key, std::string* rest) {
  const size_t colon = line.find(':');
  if (colon == std::string::npos) return false;
  *key = line.substr(0, colon);
  std::transform(key->begin(), key->end(), key->begin(), [](unsigned char c) { return std::tolower(c); });
  while (!key->empty() && std::isspace(static_cast<unsigned char>(key->back()))) key->pop_back();
  while (!key->empty() && std::isspace(static_cast<unsigned char>(key->front()))) key->erase(key->begin());
  *rest = line.substr(colon + 1);
  return true;
}

// Numbers of `text`, separated by spaces or commas.
std::vector<double> numbers(const std::string& text) {
  std::string spaced = text;
  std::replace(spaced.begin(), spaced.end(), ',', ' ');
  std::istringstream in(spaced);
  std::vector<double> out;
  for (double v; in >> v;) out.push_back(v);
  return out;
}

double number(const std::string& name, size_t line, const std::string& text, const char* key) {
  const std::vector<double> v = numbers(text);
  if (v.empty() || !std::isfinite(v[0])) fail(name, line, std::string("expected a number after '") + key + ":'");
  return v[0];
}

// Clamped uniform cubic B-spline through control points, sampled densely, then y read at
// equally spaced x (the curve's x is taken as increasing, as funcedit keeps it).
std::vector<double> sample_spline(const std::vector<Eigen::Vector2d>& control) {
  const int n = static_cast<int>(control.size());
  const int degree = std::min(3, n - 1);
  std::vector<double> knots;
  for (int i = 0; i <= degree; ++i) knots.push_back(0.0);
  for (int i = 1; i < n - degree; ++i) knots.push_back(static_cast<double>(i) / (n - degree));
  for (int i = 0; i <= degree; ++i) knots.push_back(1.0);
  std::vector<Eigen::Vector2d> curve;
  constexpr int kCurve = 4096;
  for (int s = 0; s <= kCurve; ++s) {
    const double u = std::min(static_cast<double>(s) / kCurve, 1.0 - 1e-12);
    int span = degree;
    while (span < n - 1 && knots[static_cast<size_t>(span + 1)] <= u) ++span;
    std::vector<Eigen::Vector2d> d(control.begin() + (span - degree), control.begin() + span + 1);
    for (int r = 1; r <= degree; ++r)  // de Boor
      for (int j = degree; j >= r; --j) {
        const int i = span - degree + j;
        const double denom = knots[static_cast<size_t>(i + degree - r + 1)] - knots[static_cast<size_t>(i)];
        const double a = denom > 0 ? (u - knots[static_cast<size_t>(i)]) / denom : 0.0;
        d[static_cast<size_t>(j)] = (1 - a) * d[static_cast<size_t>(j - 1)] + a * d[static_cast<size_t>(j)];
      }
    curve.push_back(d[static_cast<size_t>(degree)]);
  }
  std::vector<double> out(kSamples);
  size_t k = 0;
  for (int s = 0; s < kSamples; ++s) {
    const double x = static_cast<double>(s) / (kSamples - 1);
    while (k + 2 < curve.size() && curve[k + 1].x() < x) ++k;
    const Eigen::Vector2d& a = curve[k];
    const Eigen::Vector2d& b = curve[k + 1];
    const double t = b.x() > a.x() ? std::clamp((x - a.x()) / (b.x() - a.x()), 0.0, 1.0) : 0.0;
    out[static_cast<size_t>(s)] = a.y() + t * (b.y() - a.y());
  }
  return out;
}

// "tropism: T: x y z [A: angle] [I: intensity] [E: elasticity] [S: step]" (or "torque:", whose A:
// is read and not used) of line `line` => the movement as cpfg computes it (CPFG manual 8.1.8),
// or nothing for a line of zero T: or I: without elasticity (E: and S: 0): cpfg drops it, and
// it bends nothing. cpfg drops any other line it cannot read; here it is refused with its place.
std::optional<Movement> read_movement(const std::string& name, size_t line, const std::string& key, const std::string& rest) {
  std::string spaced = rest;
  std::replace_if(spaced.begin(), spaced.end(), [](char c) { return c == ',' || c == ':' || c == '\t'; }, ' ');
  std::istringstream in(spaced);
  const std::string head = "'" + key + ":' ";
  Movement m;
  m.torque = key == "torque";
  std::optional<Eigen::Vector3d> t;
  std::optional<double> intensity;
  std::string seen;
  for (std::string word; in >> word;) {
    if (word.size() != 1 || std::string("TAIES").find(word[0]) == std::string::npos)
      fail(name, line, head + "expected a subcommand T: A: I: E: or S:, got '" + word + "'");
    const char c = word[0];
    if (seen.find(c) != std::string::npos) fail(name, line, head + "gives '" + word + ":' twice");
    seen += c;
    std::array<double, 3> v{};
    for (int k = 0; k < (c == 'T' ? 3 : 1); ++k) {
      std::string number;
      in >> number;
      char* end = nullptr;  // strtod, not stod: stod throws for a tiny number (1e-320)
      v[static_cast<size_t>(k)] = std::strtod(number.c_str(), &end);
      if (number.empty() || end != number.c_str() + number.size() || !std::isfinite(v[static_cast<size_t>(k)]))
        fail(name, line, head + "expected " + (c == 'T' ? "three numbers" : "a number") + " after '" + word + ":'");
    }
    if (c == 'T') t = Eigen::Vector3d(v[0], v[1], v[2]);
    if (c == 'I' && !t) fail(name, line, head + "expected 'T:' before 'I:' (cpfg reads an intensity before the direction as 0 and drops the line)");
    if (c == 'I') intensity = v[0];
    if (c == 'A' && !m.torque) {
      m.cos_angle = std::cos(v[0] * std::numbers::pi / 180.0);
      m.sin_angle = std::sin(v[0] * std::numbers::pi / 180.0);
    }
    if (c == 'E') m.elasticity = v[0];
    if (c == 'S') m.step = v[0];
  }
  if (!t) fail(name, line, head + "expected 'T: x y z' (it is mandatory)");
  const double length = t->norm();
  const bool elastic = m.elasticity != 0.0 || m.step != 0.0;
  if ((length == 0.0 || (intensity && *intensity == 0.0)) && !elastic) return std::nullopt;
  if (length == 0.0) fail(name, line, head + "expected a non-zero 'T:' vector (or E: and S: 0, no tropism)");
  if (intensity && *intensity == 0.0)
    fail(name, line, head + "expected a non-zero 'I:' (cpfg drops a line of intensity 0; with E: and S: 0 it bends nothing)");
  m.direction = *t * (intensity ? std::clamp(*intensity / length, -1.0, 1.0) : 1.0 / length);
  return m;
}

// A file named on line `line` of view file `name` => refused unless it stands beside it.
void check_beside(const std::string& name, size_t line, const std::string& file) {
  if (!names_a_file_beside(file))
    fail(name, line, "'" + file + "' names a file outside the view file's folder: a view file reads only files beside "
                     "it (a relative path without '..')");
}

// "id file.s scale [i j] [texture]" of the view file's line `line` => the surface with its
// file read, or nothing when that file does not exist (cpfg then leaves the surface out); the
// file's path added to `named` either way.
std::optional<ViewSurface> read_surface_line(const std::filesystem::path& view, size_t line, const std::string& rest,
                                             std::vector<std::filesystem::path>& named) {
  const std::string name = view.string();
  std::istringstream in(rest);
  std::string id, file;
  in >> id >> file;
  if (id.size() != 1) fail(name, line, "expected a one-letter surface id after 'surface:'");
  if (file.empty()) fail(name, line, "expected 'surface: id file.s scale' (the file name after the id)");
  check_beside(name, line, file);
  ViewSurface out;
  out.id = id[0];
  out.where = name + ":" + std::to_string(line + 1) + ":1";
  if (!(in >> out.scale) || !std::isfinite(out.scale))
    fail(name, line, "expected 'surface: id file.s scale' (a number after the file name)");
  if (out.scale <= 0) out.scale = 1.0;  // as cpfg
  std::vector<double> more;
  for (double v; more.size() < 2 && in >> v;) more.push_back(v);
  if (more.size() == 2 && more[0] >= 1 && more[1] >= 1)  // a single number is a texture; 0 0 leaves it to the file
    out.precision = std::array<int, 2>{static_cast<int>(std::min(more[0], 10.0)), static_cast<int>(std::min(more[1], 10.0))};
  const std::filesystem::path target = view.parent_path() / file;
  named.push_back(target);
  std::error_code ec;
  if (!std::filesystem::exists(target, ec)) return std::nullopt;
  out.surface = read_surface_file(target);
  return out;
}

}  // namespace

SampledFunction parse_function(const std::string& name, const std::vector<std::string>& lines, size_t* pos) {
  size_t k = *pos;
  while (k < lines.size() && lines[k].find_first_not_of(" \t") == std::string::npos) ++k;
  if (k >= lines.size() || (lines[k].rfind("fver", 0) != 0 && lines[k].rfind("range:", 0) != 0))
    fail(name, k, "expected a funcedit function starting with 'fver 1 1' (or 'range:' in the older format)");
  if (lines[k].rfind("fver", 0) == 0) ++k;
  std::string key, rest;
  SampledFunction function;
  for (; k < lines.size(); ++k) {
    if (!split_key(lines[k], &key, &rest)) fail(name, k, "expected 'points: n' in the function");
    if (key == "name") std::istringstream(rest) >> function.name;
    if (key == "points") break;
  }
  if (k >= lines.size()) fail(name, k, "expected 'points: n' in the function");
  const double count = number(name, k, rest, "points");
  if (count < 2 || count > 10000 || count != std::floor(count)) fail(name, k, "expected 2 ... 10000 points");
  std::vector<Eigen::Vector2d> control;
  for (int i = 0; i < static_cast<int>(count); ++i) {
    ++k;
    const std::vector<double> xy = k < lines.size() ? numbers(lines[k]) : std::vector<double>{};
    if (xy.size() < 2 || !std::isfinite(xy[0]) || !std::isfinite(xy[1])) fail(name, k, "expected a point 'x y'");
    control.emplace_back(xy[0], xy[1]);
  }
  *pos = k + 1;
  function.samples = sample_spline(control);
  return function;
}

ViewSettings read_view_file(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::vector<std::string> lines = read_lines(path, "view file");
  ViewSettings view;
  std::optional<size_t> zero_tropism_line;  // the last "tropism direction:", when it is 0,0,0
  for (size_t i = 0; i < lines.size(); ++i) {
    std::string key, rest;
    if (!split_key(lines[i], &key, &rest)) continue;
    if (key == "angle increment") {
      view.angle = number(name, i, rest, "angle increment");
      if (!(std::abs(*view.angle) <= 360))
        fail(name, i, "expected an 'angle increment:' in [-360, 360] degrees, as lsystem.angle");
    } else if (key == "angle factor") {
      const double n = number(name, i, rest, "angle factor");
      if (!(std::abs(n) >= 1)) fail(name, i, "expected an 'angle factor:' of at least 1 in size (360 / it is the angle)");
      view.angle = 360.0 / n;
    } else if (key == "initial line width") {
      if (rest.find('p') == std::string::npos) view.initial_width = number(name, i, rest, key.c_str());
    } else if (key == "line width increment") view.width_increment = number(name, i, rest, key.c_str());
    else if (key == "tropism" || key == "torque") {
      if (std::optional<Movement> m = read_movement(name, i, key, rest)) view.movements.push_back(*m);
    } else if (key == "tropism direction") {
      const std::vector<double> v = numbers(rest);
      if (v.size() != 3 || !Eigen::Vector3d(v[0], v[1], v[2]).allFinite())
        fail(name, i, "expected 'tropism direction: x,y,z' (three numbers)");
      // cpfg divides by the length and bends only at a non-zero elasticity: 0,0,0 is no
      // tropism while the elasticity stays 0 (checked below), and stays 0.
      view.old_tropism = unit_direction(Eigen::Vector3d(v[0], v[1], v[2])).value_or(Eigen::Vector3d::Zero());
      zero_tropism_line = view.old_tropism->isZero() ? std::optional<size_t>(i) : std::nullopt;
    } else if (key == "initial elasticity") view.initial_elasticity = number(name, i, rest, key.c_str());
    else if (key == "elasticity increment") view.elasticity_increment = number(name, i, rest, key.c_str());
    else if (key == "initial scale" || key == "scale multiplier") {
      const double x = number(name, i, rest, key.c_str());
      (key == "initial scale" ? view.initial_scale : view.scale_multiplier) = x == 0.0 ? 1.0 : x;
    } else if (key == "tsurface") {
      fail(name, i, "'tsurface:' (a surface of triangles in rayshade's format, CPFG manual 8.1.5, 8.4) is not supported; "
                    "give the surface as a bezieredit '.s' file on a 'surface:' line");
    } else if (key == "surface" || key == "line") {  // cpfg reads "line:" as a surface of that id (8.1.5)
      std::optional<ViewSurface> surface = read_surface_line(path, i, rest, view.files);
      const auto same_id = [&](const ViewSurface& v) { return surface && v.id == surface->id; };
      // cpfg keeps the first surface of an id and leaves out one whose file does not exist.
      if (surface && std::none_of(view.surfaces.begin(), view.surfaces.end(), same_id))
        view.surfaces.push_back(std::move(*surface));
    } else if (key == "curve") {
      std::istringstream in(rest);
      std::string file;
      int samples = 0;
      in >> file;
      if (!(in >> samples)) samples = 100;  // cpfg's default
      if (samples < 2 || samples > 1'000'000) fail(name, i, "expected 2 ... 1000000 samples after the curve file");
      check_beside(name, i, file);
      view.files.push_back(path.parent_path() / file);
      view.curves.push_back(read_view_curve(view.files.back(), samples));
    } else if (key == "function" || key == "function set") {
      std::istringstream in(rest);
      std::string file;
      in >> file;
      const std::filesystem::path target = path.parent_path() / file;
      view.files.push_back(target);
      const std::vector<std::string> flines = read_lines(target, "function file");
      size_t pos = 0;
      size_t items = 1;
      if (key == "function set") {
        std::string k2, r2;
        if (flines.size() < 2 || !split_key(flines[1], &k2, &r2) || k2 != "items")
          fail(target.string(), 1, "expected 'items: n' after 'funcgalleryver'");
        items = static_cast<size_t>(std::max(0.0, number(target.string(), 1, r2, "items")));
        pos = 2;
      }
      for (size_t f = 0; f < items; ++f) view.functions.push_back(parse_function(target.string(), flines, &pos));
    }
  }
  if (zero_tropism_line && (view.initial_elasticity.value_or(0.0) != 0.0 || view.elasticity_increment.value_or(0.0) != 0.0))
    fail(name, *zero_tropism_line,
         "expected a non-zero 'tropism direction:' with a non-zero 'initial elasticity:' or 'elasticity increment:' "
         "(cpfg divides 0,0,0 by its length; with both 0 it is no tropism)");
  return view;
}

}  // namespace treeanim
