#pragma once
// USDA text (docs/outputs.md "USD layer"): values printed as USD's text form reads them, floats in the
// shortest text that reads back as the same float32 (std::to_chars), so a reader gets every
// value bit for bit.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace treeanim {

// "1.25", "-3e-05": the shortest round-trip text of a float or a double.
void append_usd_number(std::string& out, float value);
void append_usd_number(std::string& out, double value);

// `count` tuples of `width` floats => "[(a, b, c), (d, e, f)]" (width 1: "[a, b]").
void append_usd_tuples(std::string& out, const float* values, size_t count, int width);

// Integers => "[0, 1, 2]".
void append_usd_ints(std::string& out, const uint32_t* values, size_t count);

// A rigid transform => USD's matrix4d text: rows, row vectors, the translation in the last row.
void append_usd_matrix(std::string& out, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation);

// A quoted USD string: '"' and '\' escaped.
std::string usd_quoted(std::string_view text);

// An asset path as USD's text reads it: @path@, or @@@path@@@ when the path holds an '@' (which
// would end the first), an '@@@' in it escaped as \@@@.
std::string usd_asset_path(std::string_view path);

// Any name => a valid prim name: letters, digits and '_', not starting with a digit.
std::string usd_prim_name(std::string_view name);

}  // namespace treeanim
