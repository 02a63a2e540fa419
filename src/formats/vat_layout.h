#pragma once
// Where a vertex's texel is in a vertex animation texture (docs/outputs.md "Vertex animation
// textures"): vertex v of written frame f at column v % width, row f * rows_per_frame + v / width,
// row 0 the top of the image (the EXR's first scanline). Houdini Labs' VAT 3.0 soft-body layout.
#include <algorithm>
#include <cstddef>
#include <utility>

namespace treeanim {

// Largest texture side engines take everywhere (and the layout's width cap).
constexpr size_t kVatMaxSize = 8192;

struct VatLayout {
  size_t width = 1;           // texels per row
  size_t rows_per_frame = 1;  // rows one frame takes
  size_t height = 1;          // rows of the whole texture
  // (column, row) of vertex v in written frame f.
  std::pair<size_t, size_t> texel(size_t v, size_t f) const {
    return {v % width, f * rows_per_frame + v / width};
  }
};

// The layout of `frames` frames of `vertices` vertices, `width` texels wide (0: as wide as the
// vertices, at most kVatMaxSize, so a large mesh wraps onto several rows).
inline VatLayout vat_layout(size_t vertices, size_t frames, size_t width) {
  VatLayout layout;
  layout.width = width > 0 ? width : std::clamp<size_t>(vertices, 1, kVatMaxSize);
  layout.rows_per_frame = std::max<size_t>(1, (vertices + layout.width - 1) / layout.width);
  layout.height = std::max<size_t>(1, frames) * layout.rows_per_frame;
  return layout;
}

}  // namespace treeanim
