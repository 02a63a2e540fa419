#include "scene/scene.h"

#include <algorithm>
#include <map>
#include <sstream>

#include "common/errors.h"
#include "common/json_text.h"
#include "common/message_text.h"
#include "common/read_text_file.h"
#include "lsystem/lsystem.h"
#include "scene/lsystem_section.h"
#include "scene/output_section.h"
#include "scene/sim_sections.h"
#include "scene/species.h"
#include "scene/tree_section.h"
#include "sim/wind_keys.h"
#include "tree/tree_build_steps.h"

namespace treeanim {

namespace {

// True when `token` is a non-negative decimal integer (an array index in an override path).
bool is_index(const std::string& token) {
  return !token.empty() && token.find_first_not_of("0123456789") == std::string::npos &&
         token.size() < 10 && (token.size() == 1 || token[0] != '0');  // "00" is no index, as in a JSON pointer
}

TimeOptions read_time_options(SceneObject section) {
  TimeOptions time;
  time.fps = section.number("fps", time.fps, Range::between(1, 1000));
  time.frames = section.integer("frames", time.frames, 1, 10'000'000);
  time.start = section.integer("start", time.start, -1'000'000'000, 1'000'000'000);
  time.substeps = static_cast<int>(section.integer("substeps", time.substeps, 1, 10'000));
  time.loop = section.boolean("loop", time.loop);
  return time;
}

// Exact: the loop's two ends may differ past six digits.
std::string vector_text(const Eigen::Vector3d& v) {
  return "(" + exact_number_text(v.x()) + ", " + exact_number_text(v.y()) + ", " + exact_number_text(v.z()) + ")";
}

// time.loop => the wind made periodic over the bake (docs/scene.md "time"), or InputError
// naming what keeps the scene from looping.
void prepare_loop(SceneObject time_section, Scene& scene) {
  const TimeOptions& time = scene.time;
  if (time.frames < 2) time_section.fail("loop", "a loop needs at least 2 frames, got " + std::to_string(time.frames));
  if (scene.hsm.leaf_detach_force > 0)
    time_section.fail("loop", "leaves that detach never come back, so the bake cannot repeat; set "
                              "/hsm/leaf_detach_force to 0 or leave the loop out");
  const double start = double(time.start) / time.fps, period = double(time.frames) / time.fps;
  const WindSeam seam = wind_loop_seam(scene.wind, start, period);
  if (!seam.periodic) {
    std::ostringstream message;
    message << "the wind cannot be made periodic over the loop (" << period << " s): at its end (t = "
            << start + period << " s) it is " << vector_text(seam.last) << " m/s with gusts of " << exact_number_text(seam.last_gust)
            << " m/s, at its start (t = " << start << " s) " << vector_text(seam.first) << " m/s with gusts of "
            << exact_number_text(seam.first_gust) << " m/s; give the wind " << (scene.wind.file ? "file" : "keys")
            << " the same value at both ends (a key at t = " << start + period << " equal to the wind at t = "
            << start << ")";
    time_section.fail("loop", message.str());
  }
  scene.wind.loop_start = start;
  scene.wind.loop_period = period;
}

// Output paths of a forest of several trees must differ per tree ({tree}); a scene of one tree
// has no id to put there.
void check_tree_placeholders(const Scene& scene, const SceneReader& reader) {
  const size_t trees = scene.forest ? scene.forest->trees.size() : 1;
  for (const OutputOptions& output : scene.outputs) {
    const bool has = output.path.string().find(kTreePlaceholder) != std::string::npos;
    if (has && !scene.forest)
      reader.fail(output.pointer + "/path", "{tree} stands for the id of a tree of a /forest, and this scene has no "
                                            "/forest: remove it from the path");
    if (!has && trees > 1)
      reader.fail(output.pointer + "/path", "the forest has " + std::to_string(trees) +
                                                " trees and this path no {tree}: every tree would write the same "
                                                "file; put the tree's id in it, e.g. \"trees/{tree}.h5\"");
  }
}

// /wind/volume => every frame the scene's times need read and checked before anything is
// written, or InputError naming the file, grid and voxel.
VolumeSummary check_volume(const SceneReader& reader, const Scene& scene) {
  if (scene.time.loop)
    reader.fail("/wind/volume", "a loop needs a wind that repeats, and a volume's frames do not: leave "
                                "/time/loop or /wind/volume out");
  const double t0 = double(scene.time.start) / scene.time.fps;
  const double t1 = double(scene.time.start + scene.time.frames - 1) / scene.time.fps;
  try {
    return check_wind_volume(*scene.wind.volume, t0, t1, kMaxWindSpeed);
  } catch (const InputError& e) {
    reader.fail("/wind/volume", e.what());
  }
}

// Named in messages, cut like describe_json: a value may be a long text.
std::string override_name(const std::string& assignment) { return "--set '" + excerpt(assignment) + "'"; }

}  // namespace

AppliedOverride apply_override(Json& document, const std::string& assignment) {
  const std::string shown = override_name(assignment);
  // The file's strings were checked by the JSON parser; command-line bytes were not, and the
  // resolved scene (written into every output) must stay valid JSON text.
  try {
    (void)Json(assignment).dump();
  } catch (const nlohmann::json::type_error&) {
    throw InputError(shown + ": not valid UTF-8 text");
  }
  const size_t equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0)
    throw InputError(shown + ": expected PATH=VALUE, e.g. lsystem.iterations=6");
  const std::string path = assignment.substr(0, equals);
  const std::string text = assignment.substr(equals + 1);
  std::vector<std::string> tokens;
  for (size_t begin = 0;;) {
    const size_t dot = path.find('.', begin);
    tokens.push_back(path.substr(begin, dot == std::string::npos ? dot : dot - begin));
    if (tokens.back().empty()) throw InputError(shown + ": empty name in path '" + path + "'");
    if (tokens.size() > static_cast<size_t>(kMaxJsonDepth))
      throw InputError(shown + ": the path is deeper than " + std::to_string(kMaxJsonDepth) +
                       " levels; no scene needs more");
    if (dot == std::string::npos) break;
    begin = dot + 1;
  }
  std::string target;  // the JSON pointer the value goes to
  for (const std::string& token : tokens) target += "/" + escape_pointer_token(token);
  Json value;
  try {
    value = parse_json_text(text, shown, target);
  } catch (const JsonSyntaxError&) {
    value = text;  // not JSON: a bare string such as a file name
  }

  Json* node = &document;
  std::string pointer, made, dotted;  // dotted: the path so far, as written
  for (const std::string& token : tokens) {
    // A value not there yet: an array when the path indexes it (outputs.0.path), else an object.
    const bool absent = node->is_null();
    if (absent) {
      *node = is_index(token) ? Json::array() : Json::object();
      if (made.empty()) made = pointer;
    }
    const std::string parent = pointer;
    pointer += "/" + escape_pointer_token(token);
    if (node->is_array()) {
      if (absent && std::stoul(token) > 0)
        throw InputError(shown + ": " + parent + " is not in the scene, so its element " + token +
                         " cannot be set alone: set the whole array (--set '" + dotted + "=[...]')");
      if (!is_index(token) || std::stoul(token) > node->size())
        throw InputError(shown + ": " + pointer + " is not an index of an array of " +
                         std::to_string(node->size()) + " elements (0 ... " + std::to_string(node->size()) + ", " +
                         std::to_string(node->size()) + " appending one)");
      const size_t index = std::stoul(token);
      if (index == node->size()) {
        node->push_back(Json::object());
        if (made.empty()) made = pointer;
      }
      node = &(*node)[index];
    } else {
      if (!node->is_object())
        throw InputError(shown + ": " + pointer.substr(0, pointer.rfind('/')) +
                         " is " + describe_json(*node) + ", not an object");
      if (!node->contains(token) && made.empty()) made = pointer;
      node = &(*node)[token];
    }
    dotted += (dotted.empty() ? "" : ".") + token;
  }
  *node = std::move(value);
  return {target, made.empty() ? target : made};
}

Scene load_scene_text(const std::string& text, const std::string& name,
                      const std::filesystem::path& base_dir,
                      const std::vector<std::string>& overrides) {
  Scene scene;
  scene.resolved = parse_json_text(text, name);
  SceneReader reader(scene.resolved, base_dir, name);
  std::map<std::string, std::string> set_by;  // pointer => the override that set it
  for (const std::string& assignment : overrides) {
    const auto [target, made] = apply_override(scene.resolved, assignment);
    // As a key given twice in the file: which one was meant is no one's guess to make. A value
    // set whole after a part of it was set would drop that part unsaid (a part set after the
    // whole changes it, as asked).
    for (const auto& [earlier, by] : set_by)
      if (earlier == target || earlier.starts_with(target + "/"))
        throw InputError(override_name(assignment) + ": " + target + (earlier == target ? " is" : " holds " + earlier + ",") +
                         " set already by " + by + ": expected each path once, and a whole value before its parts");
    set_by.emplace(target, override_name(assignment));
    reader.note_override(made, override_name(assignment));  // what it made is its own
  }

  SceneObject root = reader.root();
  root.optional_string("description");
  scene.seed = static_cast<uint64_t>(root.integer("seed", 1, 0, (1LL << 53)));
  const std::optional<SpeciesChoice> species = read_species(root);
  const bool forest = root.has("forest");
  // A forest whose variants all bring their own grammar needs no top-level one.
  const bool top_lsystem = !forest || root.has("lsystem") || species;
  if (top_lsystem)
    scene.lsystem = read_lsystem_options(root.object("lsystem"), scene.seed, species ? &species->species->grammar : nullptr);
  else
    root.declare("lsystem");
  if (species) check_species_scale(*species, root.object("tree"));
  scene.tree = read_tree_options(root.object("tree"), species ? species_tree(*species) : TreeOptions{});
  scene.hsm = read_hsm_options(root.object("hsm"), species ? species_hsm(*species, HsmOptions{}) : HsmOptions{});
  scene.wind = read_wind_options(root.object("wind"), scene.seed);
  scene.time = read_time_options(root.object("time"));
  if (scene.time.loop) prepare_loop(root.object("time"), scene);
  if (forest) {
    scene.forest =
        read_forest(root.object("forest"), {scene.seed, top_lsystem ? &scene.lsystem : nullptr, &scene.tree, &scene.hsm,
                                                 species ? &*species : nullptr});
    for (const ForestVariant& variant : scene.forest->variants)
      if (scene.time.loop && variant.hsm.leaf_detach_force > 0)
        reader.fail(variant.pointer + "/hsm/leaf_detach_force",
                    "leaves that detach never come back, so the loop cannot repeat; set it to 0 or leave /time/loop out");
  }
  for (SceneObject element : root.array_of_objects("outputs")) {
    scene.outputs.push_back(read_output_options(element));
    // A loop written 1 frame in k closes evenly only when k divides its frames: else the last
    // written frame is nearer the first one's repeat than k, which a VAT's or a USD stage's
    // evenly spaced frames cannot show.
    const long long step = scene.outputs.back().frame_step, frames = scene.time.frames;
    if (scene.time.loop && frames % step != 0)
      element.fail("frame_step", "expected a frame_step that divides the loop's " + std::to_string(frames) +
                                     " frames, got " + std::to_string(step) + " (its last written frame, " +
                                     std::to_string((frames - 1) / step * step) + ", is " +
                                     std::to_string(frames - (frames - 1) / step * step) +
                                     " frames before the first comes again)");
  }
  check_tree_placeholders(scene, reader);
  reader.check_unknown_keys();
  if (scene.wind.volume) scene.volume = check_volume(reader, scene);
  scene.input_paths = reader.paths();
  // The files the grammars and view files read in turn: an edited #include is a new bake too.
  auto add_grammar_files = [&](const LsystemOptions& options) {
    for (std::filesystem::path& path : grammar_input_files(options)) scene.input_paths.push_back(std::move(path));
  };
  // And the files a custom leaf mesh is read from: a glTF's buffer edited is a new bake.
  auto add_tree_files = [&](const LsystemOptions& lsystem, const TreeOptions& tree) {
    add_grammar_files(lsystem);
    if (tree.leaf.mesh)
      for (std::filesystem::path& path : load_leaf_template(tree.leaf).files)
        scene.input_paths.push_back(std::move(path));
  };
  if (top_lsystem) add_tree_files(scene.lsystem, scene.tree);
  if (scene.forest)
    for (const ForestVariant& variant : scene.forest->variants) add_tree_files(variant.lsystem, variant.tree);
  if (scene.volume)
    for (long long frame = scene.volume->first_frame; frame <= scene.volume->last_frame; ++frame)
      scene.volume_frames.push_back(volume_frame_path(scene.wind.volume->path, frame));
  std::sort(scene.input_paths.begin(), scene.input_paths.end());
  scene.input_paths.erase(std::unique(scene.input_paths.begin(), scene.input_paths.end()), scene.input_paths.end());
  return scene;
}

Scene load_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  std::string text, reason;
  if (file.empty()) throw InputError("the scene file's path is empty: expected a scene file (.json)");
  if (!read_text_file(file, text, reason)) {
    const std::filesystem::path shown = std::filesystem::absolute(file).lexically_normal();
    throw InputError(shown.string() + ": cannot read the scene file (" + reason + ")");
  }
  const std::filesystem::path dir = std::filesystem::absolute(file).parent_path();
  Scene scene = load_scene_text(text, file.string(), dir, overrides);
  scene.file = file;
  return scene;
}

}  // namespace treeanim
