#include "scene/scene.h"

#include "common/errors.h"
#include "common/read_text_file.h"
#include "scene/sim_sections.h"

namespace treeanim {

namespace {

// Byte offset => "line:column" (1-based), for JSON syntax errors.
std::string line_column(const std::string& text, size_t offset) {
  size_t line = 1, column = 1;
  for (size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return std::to_string(line) + ":" + std::to_string(column);
}

// True when `token` is a non-negative decimal integer (an array index in an override path).
bool is_index(const std::string& token) {
  return !token.empty() && token.find_first_not_of("0123456789") == std::string::npos &&
         token.size() < 10;
}

TimeOptions read_time_options(SceneObject section) {
  TimeOptions time;
  time.fps = section.number("fps", time.fps, Range{0.0, 1000.0, true, false});
  time.frames = section.integer("frames", time.frames, 1, 10'000'000);
  time.start = section.integer("start", time.start, -1'000'000'000, 1'000'000'000);
  time.substeps = static_cast<int>(section.integer("substeps", time.substeps, 1, 10'000));
  return time;
}

}  // namespace

Json parse_scene_json(const std::string& text, const std::string& name) {
  try {
    return Json::parse(text, nullptr, true, /*ignore_comments=*/false);
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is one past the offending character; what() repeats the position, so keep
    // only nlohmann's explanation after "parse error ...: ".
    std::string what = e.what();
    const size_t colon = what.find(": ", what.find("parse error"));
    if (colon != std::string::npos) what = what.substr(colon + 2);
    const size_t at = e.byte > 0 ? e.byte - 1 : 0;
    throw InputError(name + ":" + line_column(text, at) + ": JSON syntax error: " + what);
  } catch (const nlohmann::json::out_of_range& e) {
    // A number beyond double range (1e400): nlohmann gives no offset, only the number's text
    // in quotes, so the place is where that text first occurs.
    const std::string what = e.what();
    const size_t open = what.find('\'');
    const size_t close = what.rfind('\'');
    const std::string number = open < close ? what.substr(open + 1, close - open - 1) : "";
    const size_t at = number.empty() ? std::string::npos : text.find(number);
    throw InputError(name + (at == std::string::npos ? "" : ":" + line_column(text, at)) +
                     ": JSON number out of range: " + (number.empty() ? what : number) +
                     " (expected a finite double)");
  }
}

void apply_override(Json& document, const std::string& assignment) {
  // The file's strings were checked by the JSON parser; command-line bytes were not, and the
  // resolved scene (written into every output) must stay valid JSON text.
  try {
    (void)Json(assignment).dump();
  } catch (const nlohmann::json::type_error&) {
    throw InputError("--set " + describe_json(Json(assignment)) + ": not valid UTF-8 text");
  }
  const size_t equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0)
    throw InputError("--set '" + assignment + "': expected PATH=VALUE, e.g. lsystem.iterations=6");
  const std::string path = assignment.substr(0, equals);
  const std::string text = assignment.substr(equals + 1);
  Json value;
  try {
    value = Json::parse(text);
  } catch (const nlohmann::json::parse_error&) {
    value = text;  // not JSON: a bare string such as a file name
  } catch (const nlohmann::json::out_of_range&) {
    throw InputError("--set '" + assignment + "': number out of range (expected a finite double)");
  }

  Json* node = &document;
  std::string pointer;
  size_t begin = 0;
  while (true) {
    const size_t dot = path.find('.', begin);
    const std::string token = path.substr(begin, dot == std::string::npos ? dot : dot - begin);
    if (token.empty())
      throw InputError("--set '" + assignment + "': empty name in path '" + path + "'");
    pointer += "/" + escape_pointer_token(token);
    const bool last = dot == std::string::npos;
    if (node->is_array()) {
      if (!is_index(token) || std::stoul(token) > node->size())
        throw InputError("--set '" + assignment + "': " + pointer + " is not an index of an array of " +
                         std::to_string(node->size()) + " elements");
      const size_t index = std::stoul(token);
      if (index == node->size()) node->push_back(Json::object());
      node = &(*node)[index];
    } else {
      if (node->is_null()) *node = Json::object();
      if (!node->is_object())
        throw InputError("--set '" + assignment + "': " + pointer.substr(0, pointer.rfind('/')) +
                         " is " + describe_json(*node) + ", not an object");
      node = &(*node)[token];
    }
    if (last) break;
    begin = dot + 1;
  }
  *node = std::move(value);
}

Scene load_scene_text(const std::string& text, const std::string& name,
                      const std::filesystem::path& base_dir,
                      const std::vector<std::string>& overrides) {
  Scene scene;
  scene.resolved = parse_scene_json(text, name);
  for (const std::string& assignment : overrides) apply_override(scene.resolved, assignment);

  SceneReader reader(scene.resolved, base_dir, name);
  SceneObject root = reader.root();
  root.optional_string("description");
  scene.seed = static_cast<uint64_t>(root.integer("seed", 1, 0, (1LL << 53)));
  scene.lsystem = read_lsystem_options(root.object("lsystem"), scene.seed);
  scene.tree = read_tree_options(root.object("tree"));
  scene.hsm = read_hsm_options(root.object("hsm"));
  scene.wind = read_wind_options(root.object("wind"), scene.seed);
  scene.time = read_time_options(root.object("time"));
  for (SceneObject element : root.array_of_objects("outputs"))
    scene.outputs.push_back(read_output_options(element));
  reader.check_unknown_keys();
  return scene;
}

Scene load_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  std::string text, reason;
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
