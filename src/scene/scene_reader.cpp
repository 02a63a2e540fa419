#include "scene/scene_reader.h"

#include <algorithm>
#include <cmath>

#include "common/did_you_mean.h"
#include "common/errors.h"
#include "common/input_files.h"
#include "common/message_text.h"

namespace treeanim {

namespace {

// Numbers in JSON may be integers or floats; both are accepted where a number is asked for.
bool as_finite_number(const Json& v, double* out) {
  if (!v.is_number()) return false;
  *out = v.get<double>();
  return std::isfinite(*out);
}

}  // namespace

bool Range::contains(double v) const {
  if (lo_open ? !(v > lo) : !(v >= lo)) return false;
  if (hi_open ? !(v < hi) : !(v <= hi)) return false;
  return true;
}

std::string Range::describe() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (!has_lo && !has_hi) return "a finite number";
  if (has_lo && !has_hi) return std::string("a number ") + (lo_open ? "> " : ">= ") + number_text(lo);
  if (!has_lo && has_hi) return std::string("a number ") + (hi_open ? "< " : "<= ") + number_text(hi);
  return "a number in " + std::string(lo_open ? "(" : "[") + number_text(lo) + ", " +
         number_text(hi) + (hi_open ? ")" : "]");
}

std::string describe_json(const Json& value) {
  // replace: a message must never throw, even for a string that is not UTF-8.
  std::string text = value.dump(-1, ' ', false, Json::error_handler_t::replace);
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

SceneObject::SceneObject(SceneReader* reader, Json* node, std::string pointer)
    : reader_(reader), node_(node), pointer_(std::move(pointer)) {
  reader_->register_object(pointer_);
}

std::string SceneObject::pointer_of(const std::string& key) const {
  return pointer_ + "/" + escape_pointer_token(key);
}

void SceneObject::fail(const std::string& key, const std::string& message) const {
  reader_->fail(pointer_of(key), message);
}

void SceneObject::fail_expected(const std::string& key, const std::string& expected) const {
  const Json* value = find(key);
  fail(key, "expected " + expected + ", got " + (value ? describe_json(*value) : "nothing"));
}

void SceneObject::fail_element(const std::string& key, size_t index, const std::string& expected) const {
  reader_->fail(pointer_of(key) + "/" + std::to_string(index),
                "expected " + expected + ", got " + describe_json(find(key)->at(index)));
}

const Json* SceneObject::find(const std::string& key) const {
  auto it = node_->find(key);
  return it == node_->end() ? nullptr : &*it;
}

bool SceneObject::has(const std::string& key) const {
  reader_->register_key(pointer_, key);  // a key asked about is a key of this object, given or not
  const Json* value = find(key);
  return value && !value->is_null();
}

void SceneObject::declare(const std::string& key) { reader_->register_key(pointer_, key); }

std::optional<double> SceneObject::optional_number(const std::string& key, Range range) {
  declare(key);
  const Json* value = find(key);
  if (!value || value->is_null()) return std::nullopt;
  double v = 0;
  if (!as_finite_number(*value, &v) || !range.contains(v)) fail_expected(key, range.describe());
  return v;
}

double SceneObject::number(const std::string& key, double fallback, Range range) {
  if (auto v = optional_number(key, range)) return *v;
  (*node_)[key] = fallback;
  return fallback;
}

std::optional<long long> SceneObject::optional_integer(const std::string& key, long long lo,
                                                       long long hi) {
  declare(key);
  const Json* value = find(key);
  if (!value || value->is_null()) return std::nullopt;
  const std::string expected =
      "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  // A JSON integer compared as one: 2^53 + 1 as a double is 2^53, within a bound of 2^53.
  if (value->is_number_unsigned()) {
    const uint64_t u = value->get<uint64_t>();
    if (hi < 0 || u > uint64_t(hi) || (lo > 0 && u < uint64_t(lo))) fail_expected(key, expected);
    return static_cast<long long>(u);
  }
  if (value->is_number_integer()) {
    const int64_t i = value->get<int64_t>();
    if (i < lo || i > hi) fail_expected(key, expected);
    return i;
  }
  // Written with a fraction or an exponent: a double, whose every value from 2^53 on is whole,
  // so 9007199254740992.5 would read as an integer nobody wrote.
  double v = 0;
  if (!as_finite_number(*value, &v) || std::floor(v) != v || v < double(lo) || v > double(hi))
    fail_expected(key, expected);
  if (std::fabs(v) >= 9007199254740992.0)
    fail_expected(key, expected + " (from 2^53 on, written as digits alone: with a fraction or an exponent "
                                  "the number read is whole whatever was written)");
  return static_cast<long long>(v);
}

long long SceneObject::integer(const std::string& key, long long fallback, long long lo,
                               long long hi) {
  if (auto v = optional_integer(key, lo, hi)) return *v;
  (*node_)[key] = fallback;
  return fallback;
}

bool SceneObject::boolean(const std::string& key, bool fallback) {
  declare(key);
  const Json* value = find(key);
  if (!value || value->is_null()) {
    (*node_)[key] = fallback;
    return fallback;
  }
  if (!value->is_boolean()) fail_expected(key, "true or false");
  return value->get<bool>();
}

std::optional<std::string> SceneObject::optional_string(const std::string& key) {
  declare(key);
  const Json* value = find(key);
  if (!value || value->is_null()) return std::nullopt;
  if (!value->is_string()) fail_expected(key, "a string");
  return value->get<std::string>();
}

std::string SceneObject::string(const std::string& key, const std::string& fallback) {
  if (auto v = optional_string(key)) return *v;
  (*node_)[key] = fallback;
  return fallback;
}

std::string SceneObject::choice(const std::string& key, const std::string& fallback,
                                const std::vector<std::string>& choices) {
  declare(key);
  const Json* value = find(key);
  if (!value || value->is_null()) {
    (*node_)[key] = fallback;
    return fallback;
  }
  // A value of another type is told the choices too, not only that a string was expected.
  const std::string v = value->is_string() ? value->get<std::string>() : std::string();
  if (value->is_string() && std::find(choices.begin(), choices.end(), v) != choices.end()) return v;
  std::string expected = "one of";
  for (size_t i = 0; i < choices.size(); ++i) expected += (i ? ", \"" : " \"") + choices[i] + "\"";
  const std::string near = value->is_string() ? closest_match(v, choices) : std::string();
  fail(key, "expected " + expected + ", got " + describe_json(*value) +
                (near.empty() ? "" : " (did you mean \"" + near + "\"?)"));
}

std::optional<Eigen::Vector3d> SceneObject::optional_vector3(const std::string& key, Range range) {
  declare(key);
  const Json* value = find(key);
  if (!value || value->is_null()) return std::nullopt;
  Eigen::Vector3d v;
  bool ok = value->is_array() && value->size() == 3;
  for (int i = 0; ok && i < 3; ++i) ok = as_finite_number((*value)[i], &v[i]) && range.contains(v[i]);
  const bool bounded = std::isfinite(range.lo) || std::isfinite(range.hi);
  if (!ok) fail_expected(key, bounded ? "an array of 3 numbers, each " + range.describe() : "an array of 3 finite numbers");
  return v;
}

Eigen::Vector3d SceneObject::vector3(const std::string& key, const Eigen::Vector3d& fallback, Range range) {
  if (auto v = optional_vector3(key, range)) return *v;
  (*node_)[key] = Json::array({fallback.x(), fallback.y(), fallback.z()});
  return fallback;
}

std::array<double, 2> SceneObject::pair(const std::string& key, std::array<double, 2> fallback, Range range) {
  declare(key);
  const Json* value = find(key);
  if (!value || value->is_null()) {
    (*node_)[key] = Json::array({fallback[0], fallback[1]});
    return fallback;
  }
  std::array<double, 2> v{};
  bool ok = value->is_array() && value->size() == 2;
  for (int i = 0; ok && i < 2; ++i) ok = as_finite_number((*value)[i], &v[i]) && range.contains(v[i]);
  if (!ok) fail_expected(key, "an array of 2 numbers, each " + range.describe());
  return v;
}

std::optional<std::filesystem::path> SceneObject::optional_path(const std::string& key) {
  auto text = optional_string(key);
  if (!text) return std::nullopt;
  if (text->empty()) fail_expected(key, "a non-empty path");
  // The system reads a path only up to a NUL: the file opened would not be the one named.
  if (text->find('\0') != std::string::npos) fail_expected(key, "a path without a NUL character");
  std::filesystem::path p(*text);
  if (!p.is_absolute()) p = (reader_->scene_dir() / p).lexically_normal();
  note_input_file(p);  // a scene's paths name its inputs, which no output may replace: a forest looks before it grows
  reader_->note_path(p);
  return p;
}

Json& SceneObject::declared_or(const std::string& key, Json empty) {
  declare(key);
  Json& value = (*node_)[key];  // a missing key is created as null
  if (value.is_null()) value = std::move(empty);
  return value;
}

SceneObject SceneObject::object(const std::string& key) {
  Json* value = &declared_or(key, Json::object());
  if (!value->is_object()) fail_expected(key, "an object");
  return SceneObject(reader_, value, pointer_of(key));
}

std::vector<SceneObject> SceneObject::array_of_objects(const std::string& key) {
  Json* value = &declared_or(key, Json::array());
  if (!value->is_array()) fail_expected(key, "an array of objects");
  std::vector<SceneObject> out;
  for (size_t i = 0; i < value->size(); ++i) {
    Json& element = (*value)[i];
    if (!element.is_object()) fail_element(key, i, "an object");
    out.emplace_back(reader_, &element, pointer_of(key) + "/" + std::to_string(i));
  }
  return out;
}

const Json* SceneObject::raw(const std::string& key) {
  declare(key);
  const Json* value = find(key);
  return value && !value->is_null() ? value : nullptr;
}

SceneReader::SceneReader(Json& root, std::filesystem::path scene_dir, std::string source_name)
    : root_(root), scene_dir_(std::move(scene_dir)), source_name_(std::move(source_name)) {
  if (!root_.is_object()) fail("", "expected a JSON object at the top level, got " + describe_json(root_));
}

std::string SceneReader::misspelling_of(const std::string& pointer) const {
  try {
    // From the value at fault up: while it is absent or empty, a key beside it that no reader
    // asked for and that is near its name is what was meant ("lsytem" for a missing "lsystem").
    for (std::string at = pointer; !at.empty();) {
      const size_t slash = at.rfind('/');
      const std::string parent = at.substr(0, slash);
      const Json::json_pointer place(at);
      if (root_.contains(place) && !root_.at(place).empty()) return "";
      const Json& holder = root_.at(Json::json_pointer(parent));
      const auto known = valid_keys_.find(parent);
      if (!holder.is_object() || known == valid_keys_.end()) return "";
      const std::string name = Json::json_pointer(at).back();
      // Only a key some reader asked for is one a near unknown key may have meant.
      if (std::find(known->second.begin(), known->second.end(), name) == known->second.end()) return "";
      std::vector<std::string> unknown;
      for (auto it = holder.begin(); it != holder.end(); ++it)
        if (it.key() != name && std::find(known->second.begin(), known->second.end(), it.key()) == known->second.end())
          unknown.push_back(it.key());
      if (const std::string near = closest_match(name, unknown); !near.empty())
        return " (" + printable_text(parent + "/" + escape_pointer_token(near)) + " is not a key: did you mean " + at + "?)";
      at = parent;
    }
  } catch (const std::exception&) {  // a message must never throw
  }
  return "";
}

const std::string& SceneReader::source_of(const std::string& pointer) const {
  const std::string* source = &source_name_;
  for (const auto& [target, argument] : overrides_)
    if (pointer_within(pointer, target)) source = &argument;
  return *source;
}

void SceneReader::fail(const std::string& pointer, const std::string& message) const {
  const std::string where = pointer.empty() ? std::string("/") : pointer;
  const std::string& source = source_of(pointer);
  throw InputError((source.empty() ? "" : source + ": ") + where + ": " + message + misspelling_of(pointer));
}

const std::string& SceneObject::source_name() const { return reader_->source_name(); }

const std::string& SceneObject::source_of(const std::string& key) const { return reader_->source_of(pointer_of(key)); }

const std::vector<std::pair<std::string, std::string>>& SceneObject::overrides() const { return reader_->overrides(); }

SceneObject SceneReader::root() { return SceneObject(this, &root_, ""); }

void SceneReader::register_object(const std::string& object_pointer) {
  valid_keys_.try_emplace(object_pointer);
}

void SceneReader::register_key(const std::string& object_pointer, const std::string& key) {
  auto& keys = valid_keys_[object_pointer];
  if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
}

// Recursive: the document is at most kMaxJsonDepth deep (common/json_text.h checks the text).
void SceneReader::check_object(const Json& node, const std::string& pointer) const {
  auto known = valid_keys_.find(pointer);
  if (known == valid_keys_.end()) return;  // free-form (read raw by its stage)
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string child = pointer + "/" + escape_pointer_token(it.key());
    const auto& keys = known->second;
    if (std::find(keys.begin(), keys.end(), it.key()) == keys.end()) {
      const std::string near = closest_match(it.key(), keys);
      // The key as text: a NUL in it ended the message (what() is a C string).
      fail(printable_text(child), "unknown key" + (near.empty() ? std::string()
                                                : " (did you mean " + pointer + "/" +
                                                      escape_pointer_token(near) + "?)"));
    }
    if (it->is_object()) check_object(*it, child);
    if (it->is_array())
      for (size_t i = 0; i < it->size(); ++i)
        if ((*it)[i].is_object()) check_object((*it)[i], child + "/" + std::to_string(i));
  }
}

void SceneReader::check_unknown_keys() const { check_object(root_, ""); }

}  // namespace treeanim
