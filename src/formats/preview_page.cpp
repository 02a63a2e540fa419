#include "formats/preview_page.h"

#include <algorithm>
#include <string_view>

#include "common/errors.h"
#include "preview_viewer_js.h"

namespace treeanim {

namespace {

constexpr std::string_view kDataOpen = "<script id=\"treeanim-bake\" type=\"application/json\">";
// The page's text around its title, its data and the viewer, in order.
constexpr std::string_view kHead = "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>";
constexpr std::string_view kBody = "</title>\n</head>\n<body>\n";
constexpr std::string_view kViewerOpen = "</script>\n<script>";
constexpr std::string_view kEnd = "</script>\n</body>\n</html>\n";
// The bundled viewer (its length known at compile time: a scan would take the compiler too long).
const std::string_view kViewer(kPreviewViewerJs, sizeof kPreviewViewerJs - 1);

// The title as the text of the page's title element: '&' and '<' as their references.
std::string title_text(const std::string& title) {
  std::string text;
  for (const char c : title) {
    if (c == '&') text += "&amp;";
    else if (c == '<') text += "&lt;";
    else text += c;
  }
  return text;
}

}  // namespace

std::string script_json(const nlohmann::json& data) {
  std::string dumped = data.dump();
  const size_t brackets = std::count(dumped.begin(), dumped.end(), '<');
  if (brackets == 0) return dumped;
  std::string text;
  text.reserve(dumped.size() + 5 * brackets);
  for (const char c : dumped) {
    if (c == '<') text += "\\u003c";
    else text += c;
  }
  return text;
}

std::string preview_page_text(const std::string& title, const nlohmann::json& data) {
  const std::string shown_title = title_text(title);
  std::string text;
  for (std::string_view part : {kHead, std::string_view(shown_title), kBody, kDataOpen}) text += part;
  text += script_json(data);
  for (std::string_view part : {kViewerOpen, kViewer, kEnd}) text += part;
  return text;
}

size_t preview_page_size(const std::string& title, const nlohmann::json& data) {
  size_t size = script_json(data).size() + title_text(title).size();
  for (std::string_view part : {kHead, kBody, kDataOpen, kViewerOpen, kViewer, kEnd}) size += part.size();
  return size;
}

nlohmann::json preview_page_data(const std::string& text, const std::string& source) {
  const size_t open = text.find(kDataOpen);
  const size_t close = open == std::string::npos ? open : text.find("</script>", open);
  if (close == std::string::npos)
    throw OutputError(source + ": not a treeanim preview page (no <script id=\"treeanim-bake\"> element)");
  const size_t begin = open + kDataOpen.size();
  const nlohmann::json data = nlohmann::json::parse(text.substr(begin, close - begin), nullptr, false);
  if (data.is_discarded() || !data.is_object() || data.value("format", "") != "treeanim-preview")
    throw OutputError(source + ": its treeanim-bake element is not a treeanim-preview bake");
  return data;
}

size_t longest_number_chars() {
  static const size_t chars = nlohmann::json(-1.7976931348623157e308).dump().size();
  return chars;
}

std::vector<size_t> kept_frames(size_t count, size_t stride) {
  std::vector<size_t> kept;
  for (size_t j = 0; j < count; j += stride) kept.push_back(j);
  if (count > 0 && kept.back() != count - 1) kept.push_back(count - 1);
  return kept;
}

size_t kept_frame_count(size_t count, size_t stride) {
  return count <= 1 ? count : (count - 1 + stride - 1) / stride + 1;
}

double preview_page_bytes(const PreviewPageShape& shape, bool quantized, size_t stride) {
  const size_t v = shape.vertices, f = shape.frames, number = longest_number_chars();
  const size_t kept = kept_frame_count(f, stride);
  const size_t mesh = base64_chars(12 * v) + base64_chars(12 * shape.triangles);
  // frame, then time, max_displacement, rms_displacement and wind (x y z per frame)
  const size_t plots = json_array_chars(f, shape.frame_number_chars) + 3 * json_array_chars(f, number) +
                       json_array_chars(3 * f, number);
  const size_t sample = json_array_chars(kept, f > 0 ? std::to_string(f - 1).size() : 0);
  const size_t frames = quantized ? base64_chars(6 * v * kept) + base64_chars(4 * v) : base64_chars(12 * v * kept);
  return double(shape.skeleton[quantized ? 1 : 0]) + double(mesh) + double(plots) + double(sample) + double(frames) +
         double(kPreviewNoteRoom - 2);  // the skeleton's note is ""
}

PreviewPagePlan plan_preview_page(const PreviewPageShape& shape, size_t max_page_bytes) {
  const double limit = double(max_page_bytes);
  if (const double bytes = preview_page_bytes(shape, false, 1); bytes <= limit) return {true, false, 1, bytes};
  // The bytes only fall as the stride grows (fewer frames kept): the smallest stride that fits.
  size_t too_small = 0, fits = shape.frames > 1 ? shape.frames - 1 : 1;  // frames - 1 keeps the first and the last
  if (const double bytes = preview_page_bytes(shape, true, fits); bytes > limit) return {false, true, fits, bytes};
  while (fits - too_small > 1) {
    const size_t mid = too_small + (fits - too_small) / 2;
    (preview_page_bytes(shape, true, mid) <= limit ? fits : too_small) = mid;
  }
  return {true, true, fits, preview_page_bytes(shape, true, fits)};
}

size_t further_stride(size_t kept, size_t frame_chars, size_t excess) {
  const size_t drop = frame_chars == 0 ? kept : (excess + frame_chars - 1) / frame_chars;  // frames to drop
  if (kept <= 2 || kept - 2 < drop) return 0;
  size_t too_small = 1, enough = kept - 1;  // kept - 1 keeps the first and the last
  while (enough - too_small > 1) {
    const size_t mid = too_small + (enough - too_small) / 2;
    (kept - kept_frame_count(kept, mid) >= drop ? enough : too_small) = mid;
  }
  return enough;
}

}  // namespace treeanim
