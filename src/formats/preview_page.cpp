#include "formats/preview_page.h"

#include "common/errors.h"
#include "preview_viewer_js.h"

namespace treeanim {

namespace {

constexpr std::string_view kDataOpen = "<script id=\"treeanim-bake\" type=\"application/json\">";

}  // namespace

std::string preview_page_text(const std::string& title, const nlohmann::json& data) {
  std::string text = "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" + title +
                     "</title>\n</head>\n<body>\n";
  text += kDataOpen;
  text += data.dump();
  text += "</script>\n<script>";
  text += kPreviewViewerJs;
  text += "</script>\n</body>\n</html>\n";
  return text;
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

}  // namespace treeanim
