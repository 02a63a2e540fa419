#pragma once
// The output formats as one table (src/io/output_formats.cpp), a row per format: its name, the
// scene keys it takes with their defaults, its sink and its size estimate. The scene reader,
// OutputSet, the farm's size estimates and the list in docs/outputs.md all read the rows, so a
// new format is its sink's file and a row.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "output/output_options.h"
#include "formats/outputs.h"
#include "tree/tree_model.h"

namespace treeanim {

class FrameSink;

// options, path resolved against the out folder, model, bake => a format's sink
using SinkFactory = std::unique_ptr<FrameSink>(const OutputOptions& options, const std::filesystem::path& path,
                                               const TreeModel& model, const BakeInfo& info);

// A scene key that some formats take besides format, path and frame_step; scene/ reads it
// (messages and ranges as docs/scene.md "outputs" gives them) and stores its value.
struct OutputKey {
  enum class Type : uint8_t { kBoolean, kInteger, kNumber, kChoice };
  const char* name = "";
  Type type = Type::kBoolean;
  bool optional = false;  // kInteger, kNumber: no default; when absent the option keeps its value
  double fallback = 0;    // the default: false/true as 0/1, an integer, a number, or a choice's index
  double lo = 0, hi = 0;  // kInteger, kNumber: the valid range, inclusive
  std::vector<std::string> choices = {};  // kChoice: the values
  void (*store)(OutputOptions& options, double value) = nullptr;  // value read (a choice's index) => option
};

struct OutputFormatRow {
  const char* name = "";        // /outputs/N/format
  std::vector<OutputKey> keys = {};  // in the order read, the order they take in the resolved scene
  bool always_normals = false;  // writes vertex normals without a `normals` key
  bool leaf_flags = false;      // writes FrameData::leaf_attached
  SinkFactory* make = nullptr;  // the format's sink
  // options, mesh size => bytes of one written frame's data, uncompressed (io/output_estimate.h)
  double (*frame_bytes)(const OutputOptions& options, size_t vertices, size_t triangles, size_t clusters) = nullptr;
  // options => the most bytes the output takes whatever the frames (a page that reduces its frames to fit); none: null
  double (*limit_bytes)(const OutputOptions& options) = nullptr;
};

// Every format, in the order messages and docs/outputs.md list them.
std::span<const OutputFormatRow> output_formats();
// name => its row; nullptr when no format has that name.
const OutputFormatRow* find_output_format(const std::string& name);

}  // namespace treeanim
