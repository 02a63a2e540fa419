#include "formats/usd_text.h"

#include <charconv>

namespace treeanim {

namespace {

template <typename Number>
void append_shortest(std::string& out, Number value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

}  // namespace

void append_usd_number(std::string& out, float value) { append_shortest(out, value); }
void append_usd_number(std::string& out, double value) { append_shortest(out, value); }

void append_usd_tuples(std::string& out, const float* values, size_t count, int width) {
  out += '[';
  for (size_t i = 0; i < count; ++i) {
    if (i > 0) out += ", ";
    if (width > 1) out += '(';
    for (int a = 0; a < width; ++a) {
      if (a > 0) out += ", ";
      append_shortest(out, values[i * size_t(width) + size_t(a)]);
    }
    if (width > 1) out += ')';
  }
  out += ']';
}

void append_usd_ints(std::string& out, const uint32_t* values, size_t count) {
  out += '[';
  for (size_t i = 0; i < count; ++i) {
    if (i > 0) out += ", ";
    append_shortest(out, values[i]);
  }
  out += ']';
}

void append_usd_matrix(std::string& out, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation) {
  // USD multiplies row vectors from the left: row r of the upper 3x3 is the image of axis r.
  out += '(';
  for (int r = 0; r < 4; ++r) {
    out += r > 0 ? ", (" : "(";
    for (int c = 0; c < 4; ++c) {
      if (c > 0) out += ", ";
      const double value = r < 3 ? (c < 3 ? rotation(c, r) : 0.0) : (c < 3 ? translation[c] : 1.0);
      append_shortest(out, value);
    }
    out += ')';
  }
  out += ')';
}

std::string usd_quoted(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + '"';
}

std::string usd_asset_path(std::string_view path) {
  if (path.find('@') == std::string_view::npos) return "@" + std::string(path) + "@";
  std::string out = "@@@";
  for (size_t k = 0; k < path.size(); ++k) {
    if (path.substr(k, 3) == "@@@") out += '\\';
    out += path[k];
  }
  return out + "@@@";
}

std::string usd_prim_name(std::string_view name) {
  std::string out;
  for (char c : name) {
    const bool word = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    out += word ? c : '_';
  }
  if (out.empty() || (out[0] >= '0' && out[0] <= '9')) out.insert(out.begin(), '_');
  return out;
}

}  // namespace treeanim
