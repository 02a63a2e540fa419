#pragma once
// RFC 4648 base64 (with '=' padding): how binary arrays travel inside the html page's JSON.
#include <cstddef>
#include <string>

namespace treeanim {

// bytes => their base64 text.
std::string base64(const void* data, size_t bytes);

}  // namespace treeanim
