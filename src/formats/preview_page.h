#pragma once
// The preview page's frame (docs/outputs.md "Preview page"): the HTML around the embedded bake
// and the bundled viewer. A tree's page (formats/html_sink.cpp) and the forest's (formats/html_forest.cpp)
// are written by it, and the forest's reads the trees' pages back through it.
#include <nlohmann/json.hpp>
#include <string>

namespace treeanim {

// title, the bake's JSON => the page's text: the data element, then the viewer.
std::string preview_page_text(const std::string& title, const nlohmann::json& data);

// A page's text => its embedded bake. Throws OutputError naming `source` when it holds none.
nlohmann::json preview_page_data(const std::string& text, const std::string& source);

}  // namespace treeanim
