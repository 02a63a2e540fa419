#include "formats/base64.h"

#include <cstdint>

namespace treeanim {

std::string base64(const void* data, size_t bytes) {
  static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* in = static_cast<const uint8_t*>(data);
  std::string out;
  out.reserve((bytes + 2) / 3 * 4);
  for (size_t i = 0; i < bytes; i += 3) {
    const uint32_t b0 = in[i], b1 = i + 1 < bytes ? in[i + 1] : 0, b2 = i + 2 < bytes ? in[i + 2] : 0;
    const uint32_t triple = (b0 << 16) | (b1 << 8) | b2;
    out += digits[(triple >> 18) & 63];
    out += digits[(triple >> 12) & 63];
    out += i + 1 < bytes ? digits[(triple >> 6) & 63] : '=';
    out += i + 2 < bytes ? digits[triple & 63] : '=';
  }
  return out;
}

}  // namespace treeanim
