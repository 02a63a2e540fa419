// vat_layout: texels of a frame in Houdini Labs' VAT 3.0 soft-body layout, wrapping at the width;
// the texture size check decides with the layout the writer writes.
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <gtest/gtest.h>

#include "common/errors.h"
#include "formats/vat_layout.h"
#include "formats_test_support.h"

namespace treeanim {
namespace {

TEST(VatLayout, OneRowPerFrameUpToTheWidthCap) {
  const VatLayout small = vat_layout(563, 240, 0);
  EXPECT_EQ(small.width, 563u);
  EXPECT_EQ(small.rows_per_frame, 1u);
  EXPECT_EQ(small.height, 240u);
  EXPECT_EQ(small.texel(562, 3), (std::pair<size_t, size_t>{562, 3}));
}

TEST(VatLayout, LargeMeshesWrapOntoSeveralRows) {
  const VatLayout demo = vat_layout(9293, 240, 0);
  EXPECT_EQ(demo.width, kVatMaxSize);
  EXPECT_EQ(demo.rows_per_frame, 2u);
  EXPECT_EQ(demo.height, 480u);
  EXPECT_EQ(demo.texel(8191, 0), (std::pair<size_t, size_t>{8191, 0}));
  EXPECT_EQ(demo.texel(8192, 0), (std::pair<size_t, size_t>{0, 1}));
  EXPECT_EQ(demo.texel(9292, 5), (std::pair<size_t, size_t>{1100, 11}));
  const VatLayout narrow = vat_layout(10, 3, 4);
  EXPECT_EQ(narrow.rows_per_frame, 3u);
  EXPECT_EQ(narrow.texel(9, 2), (std::pair<size_t, size_t>{1, 8}));
}

class VatTextures : public test::TempFolder {};

// Width and height of an EXR's data window.
std::pair<int, int> exr_size(const std::filesystem::path& path) {
  const Imath::Box2i window = Imf::InputFile(path.c_str()).header().dataWindow();
  return {window.max.x - window.min.x + 1, window.max.y - window.min.y + 1};
}

// The 8192-row limit decides before simulating: a bake of exactly 8192 rows is written that
// tall, one frame more is refused before anything is written, wrapped layouts alike.
TEST_F(VatTextures, TexturesAtTheSizeLimitAreWrittenAndOneFrameMoreRefused) {
  const TreeModel m = test::small_model();  // 6 vertices
  for (size_t width : {size_t(0), size_t(4)}) {
    OutputOptions options = test::output("vat", "vat/tree");
    options.texture_width = width;
    const VatLayout layout = vat_layout(m.vertex_count(), 1, width);
    const long long fit = static_cast<long long>(kVatMaxSize / layout.rows_per_frame);
    test::bake({options}, dir_, m, test::small_info(fit, 0));
    for (const char* texture : {"vat/tree.positions.exr", "vat/tree.normals.exr"})
      EXPECT_EQ(exr_size(dir_ / texture), (std::pair<int, int>{int(layout.width), int(kVatMaxSize)})) << width;
    std::filesystem::remove_all(dir_ / "vat");
    EXPECT_THROW(OutputSet({options}, dir_, m, test::small_info(fit + 1, 0)), InputError) << width;
    EXPECT_TRUE(entries().empty()) << width;
  }
}

}  // namespace
}  // namespace treeanim
