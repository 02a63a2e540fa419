#pragma once
// Typed, validated access to one JSON scene, for the options readers of every stage.
//
// Each read names the key, its default and its valid range. A missing key gets its default
// written into the JSON, so after all readers ran the document is the *resolved* scene that
// outputs record. Every key read (or declared optional) is registered as valid for its object;
// SceneReader::check_unknown_keys() then reports the first key nobody asked for, with the
// closest valid key: "/wind/sped: unknown key (did you mean /wind/speed?)".
//
// Messages: "<pointer>: expected <what>, got <value>". The caller prefixes the file name.
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/json_text.h"

namespace treeanim {

// Inclusive or exclusive bounds of a numeric value.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;  // true: value must be > lo
  bool hi_open = false;  // true: value must be < hi
  static Range any() { return {}; }
  static Range positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
  static Range non_negative() { return {0.0, std::numeric_limits<double>::infinity(), false, false}; }
  static Range between(double lo, double hi) { return {lo, hi, false, false}; }
  static Range at_least(double lo) { return {lo, std::numeric_limits<double>::infinity(), false, false}; }
  bool contains(double v) const;
  std::string describe() const;  // "a number in [0, 1]", "a number > 0", ...
};

class SceneReader;

// One JSON object of the scene (a section such as /wind, or an element of /outputs).
class SceneObject {
 public:
  SceneObject(SceneReader* reader, Json* node, std::string pointer);

  double number(const std::string& key, double fallback, Range range = Range::any());
  std::optional<double> optional_number(const std::string& key, Range range = Range::any());
  long long integer(const std::string& key, long long fallback, long long lo, long long hi);
  std::optional<long long> optional_integer(const std::string& key, long long lo, long long hi);
  bool boolean(const std::string& key, bool fallback);
  std::string string(const std::string& key, const std::string& fallback);
  std::optional<std::string> optional_string(const std::string& key);
  // One of `choices`; the message lists them.
  std::string choice(const std::string& key, const std::string& fallback,
                     const std::vector<std::string>& choices);
  // Three finite numbers, each within `range`.
  Eigen::Vector3d vector3(const std::string& key, const Eigen::Vector3d& fallback, Range range = Range::any());
  std::optional<Eigen::Vector3d> optional_vector3(const std::string& key, Range range = Range::any());
  // Two finite numbers, each within `range` ([x, z] on the ground, a [lo, hi] interval).
  std::array<double, 2> pair(const std::string& key, std::array<double, 2> fallback, Range range = Range::any());
  // A path string resolved against the scene file's folder (absolute paths kept).
  std::optional<std::filesystem::path> optional_path(const std::string& key);

  // Nested object; created as {} when missing. Its keys are checked for unknowns too.
  SceneObject object(const std::string& key);
  // Whether the key is given: present with a value other than null (null takes the default).
  bool has(const std::string& key) const;
  // Array whose elements must all be objects; [] when missing (and written as []).
  std::vector<SceneObject> array_of_objects(const std::string& key);
  // A value the caller parses itself (free-form maps, strings lists); nullptr when missing.
  // Its content is not checked for unknown keys.
  const Json* raw(const std::string& key);

  // Declares `key` valid without reading it (read elsewhere, e.g. by another stage).
  void declare(const std::string& key);
  // "<pointer>/<key>" with JSON-pointer escaping.
  std::string pointer_of(const std::string& key) const;
  const std::string& pointer() const { return pointer_; }
  // The scene file's name as messages give it ("" when none).
  const std::string& source_name() const;
  // What messages about `key` name as its source: the override that set it, else source_name().
  const std::string& source_of(const std::string& key) const;
  // (pointer, "--set '...'") of each value the command line gave, in the order given.
  const std::vector<std::pair<std::string, std::string>>& overrides() const;
  // The object as read so far (defaults of the keys read are filled in).
  const Json& json() const { return *node_; }
  // Throws InputError "<pointer>/<key>: <message>".
  [[noreturn]] void fail(const std::string& key, const std::string& message) const;
  // Throws InputError "<pointer>/<key>: expected <expected>, got <value>".
  [[noreturn]] void fail_expected(const std::string& key, const std::string& expected) const;
  // Throws InputError "<pointer>/<key>/<index>: expected <expected>, got <element>".
  [[noreturn]] void fail_element(const std::string& key, size_t index, const std::string& expected) const;

 private:
  const Json* find(const std::string& key) const;
  // key, the empty value of its type => its value, declared; absent or null becomes `empty`.
  Json& declared_or(const std::string& key, Json empty);
  SceneReader* reader_;
  Json* node_;
  std::string pointer_;
};

class SceneReader {
 public:
  // root: the scene document (modified in place to the resolved scene).
  // scene_dir: folder that relative paths are resolved against.
  // source_name: prefixes every message ("scene.json: /time/fps: ..."); may be empty.
  SceneReader(Json& root, std::filesystem::path scene_dir, std::string source_name = "");

  SceneObject root();
  const std::filesystem::path& scene_dir() const { return scene_dir_; }
  const std::string& source_name() const { return source_name_; }
  // Throws InputError "<source>: <pointer>: <message>", the source as source_of(pointer).
  [[noreturn]] void fail(const std::string& pointer, const std::string& message) const;
  // The value at `pointer` => the override that set it ("--set 'time.fps=5000'"), else source_name().
  const std::string& source_of(const std::string& pointer) const;
  // Throws InputError for the first key (in document order) no reader declared.
  void check_unknown_keys() const;
  // Called by SceneObject: marks key valid for the object at pointer.
  void register_key(const std::string& object_pointer, const std::string& key);
  void register_object(const std::string& object_pointer);
  // Called by SceneObject::optional_path: the files the scene names, in the order read.
  void note_path(const std::filesystem::path& path) { paths_.push_back(path); }
  // The value at `pointer`, and all below it, came from the command line: a message about it
  // names `argument` ("--set 'time.fps=5000'"), not the scene file.
  void note_override(std::string pointer, std::string argument) {
    overrides_.emplace_back(std::move(pointer), std::move(argument));
  }
  const std::vector<std::filesystem::path>& paths() const { return paths_; }
  const std::vector<std::pair<std::string, std::string>>& overrides() const { return overrides_; }

 private:
  void check_object(const Json& node, const std::string& pointer) const;
  // The value at `pointer` is at fault => " (/lsytem is not a key: did you mean /lsystem?)" when
  // it, or an object it lies in, is absent or empty beside a near key no reader asked for; else "".
  std::string misspelling_of(const std::string& pointer) const;
  Json& root_;
  std::filesystem::path scene_dir_;
  std::string source_name_;
  std::map<std::string, std::vector<std::string>> valid_keys_;  // object pointer => keys
  std::vector<std::filesystem::path> paths_;
  std::vector<std::pair<std::string, std::string>> overrides_;  // pointer, argument
};

// Compact one-line rendering of a JSON value for messages (strings quoted, long values cut).
std::string describe_json(const Json& value);

}  // namespace treeanim
