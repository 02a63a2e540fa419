// vat_layout: texels of a frame in Houdini Labs' VAT 3.0 soft-body layout, wrapping at the width.
#include <gtest/gtest.h>

#include "formats/vat_layout.h"

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

}  // namespace
}  // namespace treeanim
