#include "scene/sim_sections.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <string_view>
#include <utility>

#include "common/direction.h"
#include "common/errors.h"
#include "common/frame_field.h"
#include "common/message_text.h"
#include "common/read_text_file.h"

namespace treeanim {

namespace {

// Wind speed and gust amplitude, m/s: no recorded gust exceeds 113 m/s (Barrow Island, 1996), so a
// larger value is a slip (1,000,000 for 10), not a storm.
const Range kWindSpeed = Range::between(0, kMaxWindSpeed);
// A wind key's time, s: a bake reaches 10^9 frames from 0 (time.start) at 1 fps or more, and
// within this range the time between two keys, which the air divides by, stays finite.
const Range kWindTime = Range::between(-1e10, 1e10);

// A solver frequency, rad/s: at the shortest step the time keys allow (1000 fps, 10,000 substeps)
// the solver resolves up to pi/(2h) = 1.57e7 rad/s; a larger cap or floor resolves nothing more.
const Range kSolverFrequency = {0, 1.5e7, true, false};

// The hsm keys that one stiffness mode reads and the other does not (docs/solver.md, "Stiffness").
constexpr std::pair<const char*, StiffnessMode> kModeKeys[] = {
    {"alpha", StiffnessMode::kPerStep},
    {"k_d", StiffnessMode::kPerStep},
    {"global_scale", StiffnessMode::kPhysical},
    {"max_frequency", StiffnessMode::kPhysical},
    {"max_limb_frequency", StiffnessMode::kPhysical},
    {"min_limb_frequency", StiffnessMode::kPhysical},
};

// One field of a CSV line => finite number within `range`; throws "name:line: column 'what': ...".
double csv_number(std::string_view cell, const std::string& where, const std::string& column,
                  const Range& range = Range::any()) {
  // strtod, not stod: a subnormal such as 4e-320 is a number (stod throws on its ERANGE). It
  // reads up to a NUL, which a cell of the file's text has not: a copy kept for every cell.
  thread_local std::string text;
  text.assign(cell);
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  size_t used = static_cast<size_t>(end - text.c_str());
  while (used < text.size() && (text[used] == ' ' || text[used] == '\t' || text[used] == '\r')) ++used;
  // strtod also reads C's hexadecimal ("0x10", "0x1p4"), which no CSV writer means.
  const bool hexadecimal = cell.find_first_of("xXpP") != std::string_view::npos;
  if (used == 0 || used != text.size() || !std::isfinite(v) || hexadecimal)
    throw InputError(where + ": column '" + column + "': expected a finite number, got '" + excerpt(cell) + "'");
  if (!range.contains(v))
    throw InputError(where + ": column '" + column + "': expected " + range.describe() + ", got '" + excerpt(cell) +
                     "'");
  return v;
}

// The cells of one CSV line as views into it, surrounding blanks removed; only the first
// kMaxCells are kept, `count` is all of them.
constexpr size_t kMaxCells = 6;
struct CsvCells {
  std::array<std::string_view, kMaxCells> cell;
  size_t count = 0;
};
CsvCells split_csv_line(std::string_view line) {
  CsvCells cells;
  size_t begin = 0;
  while (true) {
    const size_t comma = std::min(line.find(',', begin), line.size());
    std::string_view cell = line.substr(begin, comma - begin);
    const size_t b = cell.find_first_not_of(" \t\r");
    const size_t e = cell.find_last_not_of(" \t\r");
    cell = b == std::string_view::npos ? std::string_view() : cell.substr(b, e - b + 1);
    if (cells.count < kMaxCells) cells.cell[cells.count] = cell;
    ++cells.count;
    if (comma == line.size()) return cells;
    begin = comma + 1;
  }
}

// Keys must have strictly increasing times (interpolation needs an order) => "" when key i
// is in order, else the message.
std::string order_error(const std::vector<WindKey>& keys, size_t i) {
  if (i == 0 || keys[i].time > keys[i - 1].time) return "";
  return "time " + number_text(keys[i].time) + " must be greater than the previous key's time " +
         number_text(keys[i - 1].time);
}

// /wind/volume => where the volume's frames are, how they are timed and placed.
VolumeOptions read_volume_options(SceneObject section) {
  VolumeOptions o;
  const std::optional<std::filesystem::path> path = section.optional_path("path");
  if (!path) section.fail("path", "expected the volume's frame files, e.g. \"smoke/vel.####.vdb\"");
  FrameField field;
  if (!read_frame_field(path->filename().string(), field))
    section.fail("path", "expected at most one frame number in the file name, as #### or %04d (at most " +
                             std::to_string(kMostFrameDigits) + " digits), got '" + path->filename().string() + "'");
  o.path = *path;
  o.grid = section.string("grid", o.grid);
  if (o.grid.empty()) section.fail("grid", "expected a grid's name, e.g. \"vel\"");
  // Volume caches are written at a shot's frame rate; as time.fps.
  o.fps = section.number("fps", o.fps, Range::between(1, 1000));
  o.first_frame = section.integer("first_frame", o.first_frame, -1'000'000'000, 1'000'000'000);
  o.z_up = section.choice("up", "y", {"y", "z"}) == "z";
  const std::string outside = section.choice("outside", "keys", {"keys", "calm", "edge"});
  o.outside = outside == "keys"   ? VolumeOutside::kKeys
              : outside == "calm" ? VolumeOutside::kCalm
                                  : VolumeOutside::kEdge;
  // From micrometres to kilometres per unit: a cache in any length unit a tool writes.
  o.units = section.number("units", o.units, Range::between(1e-6, 1000));
  o.rotate = section.number("rotate", o.rotate, Range::between(-360, 360));
  // As far as a forest reaches (its spacing is at most 1 km, its trees a few thousand).
  o.translate = section.vector3("translate", o.translate, Range::between(-1e6, 1e6));
  return o;
}

}  // namespace

HsmOptions read_hsm_options(SceneObject section, HsmOptions o) {
  o.global_matching = section.boolean("global_matching", o.global_matching);
  o.stiffness = section.choice("stiffness", o.stiffness == StiffnessMode::kPhysical ? "physical" : "per_step", {"physical", "per_step"}) == "physical"
                    ? StiffnessMode::kPhysical
                    : StiffnessMode::kPerStep;
  const bool physical = o.stiffness == StiffnessMode::kPhysical;
  // A key of the other mode would be read past while its scene expects it to matter: refused,
  // and left out of the resolved scene, which so reads back in its own mode.
  for (const auto& [key, mode] : kModeKeys)
    if (mode != o.stiffness) {
      if (section.has(key))
        section.fail_expected(key, std::string("no ") + key + " where stiffness is \"" + (physical ? "physical" : "per_step") +
                                       "\" (" + key + " is read by \"stiffness\": \"" +
                                       (physical ? "per_step" : "physical") + "\" alone)");
      section.declare(key);
    }
  if (!physical) {
    o.alpha = section.number("alpha", o.alpha, Range::between(0, 1));
    o.k_d = section.number("k_d", o.k_d, Range::between(0, 1));
  }
  o.leaf_alpha = section.number("leaf_alpha", o.leaf_alpha, Range::between(0, 1));
  o.leaf_turn = section.number("leaf_turn", o.leaf_turn, Range::between(0, 1));
  o.yield_strain = section.number("yield_strain", o.yield_strain, {0, 0.1, true, false});
  o.root_flexibility = section.number("root_flexibility", o.root_flexibility, Range::between(0, 100));
  // Below ~1 MPa (softer than any self-supporting plant tissue; green wood is 5-12 GPa) a
  // branch has no stiffness to speak of and the wind carries the tree away.
  o.youngs_modulus = section.number("youngs_modulus", o.youngs_modulus, Range::between(1e6, 5e10));
  if (physical) {
    o.global_scale = section.number("global_scale", o.global_scale, Range::between(0, 100));
    o.max_frequency = section.number("max_frequency", o.max_frequency, kSolverFrequency);
    o.max_limb_frequency = section.number("max_limb_frequency", o.max_limb_frequency, kSolverFrequency);
    // A cap set below the default floor takes the floor down with it: the floor guards vanishing
    // limbs, and a scene that asks for slower limbs than it has said nothing against.
    o.min_limb_frequency = section.number("min_limb_frequency", std::min(o.min_limb_frequency, o.max_limb_frequency),
                                          Range::between(0, 1.5e7));
    // Both given and crossed: which would win is no one's guess to make.
    if (o.min_limb_frequency > o.max_limb_frequency)
      section.fail("min_limb_frequency", "the floor " + number_text(o.min_limb_frequency) +
                                             " rad/s is above max_limb_frequency, " + number_text(o.max_limb_frequency) +
                                             " rad/s: expected a floor at or below the cap");
  }
  o.damping_ratio = section.number("damping_ratio", o.damping_ratio, Range::between(0, 10));
  o.leaf_detach_force = section.number("leaf_detach_force", o.leaf_detach_force, Range::between(0, 1e4));
  o.gravity = section.vector3("gravity", o.gravity, Range::between(-100, 100));
  o.sleep = section.boolean("sleep", o.sleep);
  o.sleep_velocity = section.number("sleep_velocity", o.sleep_velocity, {0, 1, true, false});
  o.sleep_distance = section.number("sleep_distance", o.sleep_distance, {0, 1, true, false});
  o.rotation_iterations =
      static_cast<int>(section.integer("rotation_iterations", o.rotation_iterations, 1, 100));
  o.precision = section.choice("precision", o.precision == Precision::kDouble ? "double" : "float", {"double", "float"}) == "double" ? Precision::kDouble
                                                                                       : Precision::kFloat;
  o.particles = section.choice("particles", o.particles == ParticleMode::kVertices ? "vertices" : "samples", {"vertices", "samples"}) == "vertices"
                    ? ParticleMode::kVertices
                    : ParticleMode::kSamples;
  // Per-step rates of 0 for both terms leave nothing holding the tree: refuse, not bake a
  // tree that blows away.
  if (!physical && o.alpha == 0 && (o.k_d == 0 || !o.global_matching))
    section.fail("alpha", "expected a number in (0, 1] when k_d is 0 or global_matching is off "
                          "(nothing would hold the tree), got 0");
  return o;
}

std::vector<WindKey> parse_wind_csv(std::string_view text, const std::string& name) {
  // A key a line, read in place: a file near the size limit (kMaxTextFileBytes) holds some 10^7
  // keys, so neither the text nor its lines are copied, and the keys are reserved at once.
  std::vector<WindKey> keys;
  keys.reserve(static_cast<size_t>(std::count(text.begin(), text.end(), '\n')) + 1);
  size_t line_number = 0;
  bool header_seen = false;
  bool has_gust = false;
  for (size_t start = 0; start < text.size();) {
    const size_t newline = std::min(text.find('\n', start), text.size());
    const std::string_view line = text.substr(start, newline - start);
    start = newline + 1;
    ++line_number;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    const std::string where = name + ":" + std::to_string(line_number);
    const CsvCells cells = split_csv_line(line);
    if (!header_seen) {
      constexpr std::string_view expected[] = {"time", "speed", "dx", "dy", "dz", "gust"};
      const bool named = (cells.count == 5 || cells.count == 6) &&
                         std::equal(cells.cell.begin(), cells.cell.begin() + cells.count, expected);
      if (!named)
        throw InputError(where + ": expected the header 'time,speed,dx,dy,dz' or "
                         "'time,speed,dx,dy,dz,gust', got '" + excerpt(line) + "'");
      has_gust = cells.count == 6;
      header_seen = true;
      continue;
    }
    const size_t columns = has_gust ? 6 : 5;
    if (cells.count != columns)
      throw InputError(where + ": expected " + std::to_string(columns) + " comma-separated values, got " +
                       std::to_string(cells.count));
    WindKey key;
    key.time = csv_number(cells.cell[0], where, "time", kWindTime);
    key.speed = csv_number(cells.cell[1], where, "speed", kWindSpeed);
    const Eigen::Vector3d d(csv_number(cells.cell[2], where, "dx"), csv_number(cells.cell[3], where, "dy"),
                            csv_number(cells.cell[4], where, "dz"));
    const auto direction = unit_direction(d);
    if (!direction) throw InputError(where + ": columns 'dx,dy,dz': the direction must not be zero");
    key.direction = *direction;
    if (has_gust) key.gust = csv_number(cells.cell[5], where, "gust", kWindSpeed);
    keys.push_back(key);
    if (const std::string error = order_error(keys, keys.size() - 1); !error.empty())
      throw InputError(where + ": " + error);
  }
  if (!header_seen)
    throw InputError(name + ":1: expected the header 'time,speed,dx,dy,dz[,gust]', the file " +
                     (line_number > 0 ? "holds comments and blank lines only" : "is empty"));
  if (keys.empty()) throw InputError(name + ":" + std::to_string(line_number) + ": expected at least one data line after the header");
  return keys;
}

WindOptions read_wind_options(SceneObject section, uint64_t scene_seed) {
  WindOptions o;
  o.file = section.optional_path("file");
  std::vector<SceneObject> key_objects = section.array_of_objects("keys");
  if (o.file && !key_objects.empty())
    section.fail("keys", "give either /wind/keys or /wind/file, not both");
  for (size_t i = 0; i < key_objects.size(); ++i) {
    SceneObject& k = key_objects[i];
    WindKey key;
    key.time = k.number("time", 0, kWindTime);
    key.speed = k.number("speed", 0, kWindSpeed);
    const auto direction = unit_direction(k.vector3("direction", key.direction));
    if (!direction) k.fail("direction", "expected a non-zero vector");
    key.direction = *direction;
    key.gust = k.number("gust", 0, kWindSpeed);
    o.keys.push_back(key);
    if (const std::string error = order_error(o.keys, i); !error.empty()) k.fail("time", error);
  }
  if (o.file) {
    std::string text, reason;
    if (!read_text_file(*o.file, text, reason))
      section.fail("file", "cannot open wind file '" + o.file->string() + "' (" + reason + ")");
    o.keys = parse_wind_csv(text, o.file->string());
  }
  o.air_density = section.number("air_density", o.air_density, Range::between(0, 1.6));
  o.branch_drag_coefficient = section.number("branch_drag_coefficient", o.branch_drag_coefficient, Range::between(0, 10));
  o.leaf_drag_coefficient = section.number("leaf_drag_coefficient", o.leaf_drag_coefficient, Range::between(0, 10));
  o.turbulence_intensity = section.number("turbulence_intensity", o.turbulence_intensity, Range::between(0, 10));
  // At least a millimetre, below any leaf: a length near 0 makes the eddies' wavenumbers overflow.
  o.turbulence_length = section.number("turbulence_length", o.turbulence_length, Range::between(1e-3, 1000));
  o.turbulence_frequency = section.number("turbulence_frequency", o.turbulence_frequency, Range::between(0, 1000));
  o.turbulence_modes = static_cast<int>(section.integer("turbulence_modes", o.turbulence_modes, 1, 64));
  o.gust_frequency = section.number("gust_frequency", o.gust_frequency, Range::between(0, 10));
  // At most 2^53, as every seed: the largest integer JSON keeps exact.
  o.seed = static_cast<uint64_t>(section.integer("seed", static_cast<long long>(scene_seed), 0, 1LL << 53));
  // Read only when given, so that a scene without it resolves as before.
  if (section.has("volume")) o.volume = read_volume_options(section.object("volume"));
  return o;
}

}  // namespace treeanim
