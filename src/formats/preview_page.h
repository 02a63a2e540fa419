#pragma once
// The preview page's frame (docs/outputs.md "Preview page"): the HTML around the embedded bake
// and the bundled viewer, and the arithmetic of its size. A tree's page (formats/html_sink.cpp) and the
// forest's (formats/html_forest.cpp) are written by it, and the forest's reads the trees' pages back
// through it.
#include <array>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace treeanim {

struct BakeInfo;
struct OutputOptions;
struct TreeModel;

// title, the bake's JSON => the page's text: the data element, then the viewer.
std::string preview_page_text(const std::string& title, const nlohmann::json& data);

// preview_page_text(title, data).size(), without the copy of the viewer.
size_t preview_page_size(const std::string& title, const nlohmann::json& data);

// JSON => its text inside the page's data element: '<' written as the JSON escape \u003c, so
// that no name in it ("<!--<script" in a file name) changes where the browser ends the element.
std::string script_json(const nlohmann::json& data);

// A page's text => its embedded bake. Throws OutputError naming `source` when it holds none.
nlohmann::json preview_page_data(const std::string& text, const std::string& source);

// Characters of the longest number the page's JSON prints: a double at its longest
// ("-1.7976931348623157e+308"; an int64 takes at most 20).
size_t longest_number_chars();

// Characters the page's JSON keeps for its note ("reduced"), quotes included: room for a tree's
// note and for the forest page's, which may quote one, so that a forest page of one tree is never
// larger than that tree's page was planned to be.
inline constexpr size_t kPreviewNoteRoom = 1024;

// Base64 characters of `bytes` bytes.
inline constexpr size_t base64_chars(size_t bytes) { return (bytes + 2) / 3 * 4; }

// Characters of `count` JSON array elements of at most `chars` characters each, commas included.
inline constexpr size_t json_array_chars(size_t count, size_t chars) { return count == 0 ? 0 : count * (chars + 1) - 1; }

// count frames, stride => those kept: 0, stride, 2 stride, ..., and always the last.
std::vector<size_t> kept_frames(size_t count, size_t stride);

// How many kept_frames() keeps, without listing them.
size_t kept_frame_count(size_t count, size_t stride);

// What sizes a tree's page, known before its first frame.
struct PreviewPageShape {
  size_t vertices = 0, triangles = 0;
  size_t frames = 0;                  // written frames: each one is plotted
  size_t frame_number_chars = 20;     // characters of the longest frame number plotted
  std::array<size_t, 2> skeleton{};   // the text with every array, base64 text and the note empty and
                                      // every number at its longest: [0] float32 frames, [1] int16
};

// An upper bound of the page's bytes when it keeps every stride-th frame (kept_frames()) as
// float32 positions or, `quantized`, as int16 displacements with their steps; the plots keep every
// frame, each number at its longest, and the note takes kPreviewNoteRoom.
double preview_page_bytes(const PreviewPageShape& shape, bool quantized, size_t stride);

// How a tree's page holds its frames: the first that fits of every frame as float32, every frame
// as int16, and every stride-th as int16 at the smallest stride that fits.
struct PreviewPagePlan {
  bool fits = false;       // false: not even the first and last frame fit as int16
  bool quantized = false;  // int16 displacements, else float32 positions
  size_t stride = 1;       // kept frames: kept_frames(frames, stride)
  double bytes = 0;        // preview_page_bytes() of the plan (when !fits: of the first and last frame as int16)
};
PreviewPagePlan plan_preview_page(const PreviewPageShape& shape, size_t max_page_bytes);

// The shape of the page an html output writes of `model` in `info`'s bake, as its sink plans it
// (formats/html_sink.cpp): the page named after `options.path`, and the forest page of this tree alone.
PreviewPageShape html_page_shape(const OutputOptions& options, const TreeModel& model, const BakeInfo& info);

// kept frames, base64 characters of each, characters over the limit => the smallest further
// stride over the kept frames (kept_frames(kept, k)) that drops at least that many characters;
// 0 when even keeping two of them does not.
size_t further_stride(size_t kept, size_t frame_chars, size_t excess);

}  // namespace treeanim
