#pragma once
// The output formats as one table (src/output/output_formats.cpp), a row per format: its name,
// the scene keys it takes with their defaults, what it writes besides positions and its size
// estimate. No dependencies, so that scene/ reads the keys without linking a writer; each row's
// sink is made in formats/ (formats/sink_factories.h). The scene reader, OutputSet, the farm's
// size estimates and the lists in docs/outputs.md and docs/design.md all read the rows.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "output/output_options.h"

namespace treeanim {

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
  bool skinned = false;         // writes joints and their keys (usd: with its `skinned` key)
  // The extension its path must end in, and what the file is ("" / nullptr: any path)
  const char* path_extension = "";
  const char* file_kind = nullptr;
  // options, mesh size => bytes of one written frame's data, uncompressed (formats/output_estimate.h)
  double (*frame_bytes)(const OutputOptions& options, size_t vertices, size_t triangles, size_t clusters) = nullptr;
  // the same => bytes written once, whatever the frame count (the rest mesh, joints); nullptr: none
  double (*fixed_bytes)(const OutputOptions& options, size_t vertices, size_t triangles, size_t clusters) = nullptr;
};

// The output writes one joint per cluster (skinned, no limbs merged under max_joints).
bool joint_per_cluster(const OutputOptions& options, size_t clusters);

// Every format, in the order messages and docs/outputs.md list them.
std::span<const OutputFormatRow> output_formats();
// name => its row; nullptr when no format has that name.
const OutputFormatRow* find_output_format(const std::string& name);

}  // namespace treeanim
