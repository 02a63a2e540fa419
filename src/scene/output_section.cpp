#include "scene/output_section.h"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <vector>

#include "common/message_text.h"
#include "output/output_formats.h"

namespace treeanim {

namespace {

// A key of the element's format => its value (its default when absent) stored in `options`.
void read_format_key(SceneObject& element, const OutputKey& key, OutputOptions& options) {
  std::optional<double> value;
  switch (key.type) {
    case OutputKey::Type::kBoolean:
      value = element.boolean(key.name, key.fallback != 0) ? 1.0 : 0.0;
      break;
    case OutputKey::Type::kInteger: {
      const auto lo = static_cast<long long>(key.lo), hi = static_cast<long long>(key.hi);
      if (!key.optional) value = double(element.integer(key.name, static_cast<long long>(key.fallback), lo, hi));
      else if (auto n = element.optional_integer(key.name, lo, hi)) value = double(*n);
      break;
    }
    case OutputKey::Type::kNumber: {
      const Range range = Range::between(key.lo, key.hi);
      value = key.optional ? element.optional_number(key.name, range) : element.number(key.name, key.fallback, range);
      break;
    }
    case OutputKey::Type::kChoice: {
      const std::string chosen = element.choice(key.name, key.choices.at(size_t(key.fallback)), key.choices);
      value = double(std::find(key.choices.begin(), key.choices.end(), chosen) - key.choices.begin());
      break;
    }
  }
  if (value) key.store(options, *value);
}

}  // namespace

OutputOptions read_output_options(SceneObject element) {
  OutputOptions options;
  options.pointer = element.pointer();
  options.source = element.source_of("path");  // most messages about an output are about its file
  std::vector<std::string> formats;
  for (const OutputFormatRow& row : output_formats()) formats.emplace_back(row.name);
  if (!element.raw("format")) {  // null is absent (docs/scene.md), as everywhere
    std::string listed;
    for (const std::string& format : formats) listed += (listed.empty() ? "" : ", ") + format;
    element.fail("format", "required (one of " + listed + ")");
  }
  options.format = find_output_format(element.choice("format", "", formats));
  const auto path = element.optional_string("path");
  if (!path || path->empty()) element.fail_expected("path", "a non-empty path string");
  // The system reads a path only up to a NUL, and the files that name this one (an OBJ's mtllib,
  // a USD reference, the forest's manifest) are lines of text: a control character breaks both.
  if (std::any_of(path->begin(), path->end(), [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; }))
    element.fail_expected("path", "a path without control characters (NUL, newline, tab, ...)");
  options.path = *path;
  // A file's name, not a folder's: "out/" or "out/." would write the hidden file "out/.pc2" (or
  // fail once the whole bake is done, where the folder stands).
  if (const std::string name = options.path.filename().string(); name.empty() || name == "." || name == "..")
    element.fail("path", "expected the path of a file, got \"" + excerpt(*path) + "\", which names a folder");
  if (*options.format->path_extension && options.path.extension() != options.format->path_extension)
    element.fail("path", std::string(options.format->file_kind) + " whose name ends in " +
                             options.format->path_extension + " (e.g. \"" +
                             std::filesystem::path(options.path).replace_extension(options.format->path_extension).string() +
                             "\"), got \"" + excerpt(*path) + "\"");
  options.frame_step = static_cast<int>(element.integer("frame_step", 1, 1, 1000000));
  for (const OutputKey& key : options.format->keys) read_format_key(element, key, options);
  // Joints are a skinned output's: a plain USD has none to cap.
  if (element.has("max_joints") && !options.format->skinned && !options.skinned)
    element.fail("max_joints", "applies to a skinned output (skinned_glb, or usd with \"skinned\": true)");
  if (options.format->always_normals) options.normals = true;
  return options;
}

}  // namespace treeanim
