#include "common/frame_field.h"

#include <gtest/gtest.h>

namespace treeanim {
namespace {

// name => its file at frame 7, or "refused".
std::string frame_7(const std::string& name) {
  FrameField field;
  return read_frame_field(name, field) ? with_frame_number(name, field, 7) : "refused";
}

TEST(FrameField, HoudinisHashesAndPrintfsFieldsNameTheFrame) {
  EXPECT_EQ(frame_7("vel.####.vdb"), "vel.0007.vdb");
  EXPECT_EQ(frame_7("vel.#.vdb"), "vel.7.vdb");
  EXPECT_EQ(frame_7("vel.%d.vdb"), "vel.7.vdb");
  EXPECT_EQ(frame_7("vel.%04d.vdb"), "vel.0007.vdb");
  EXPECT_EQ(frame_7("vel.%012d.vdb"), "vel.000000000007.vdb");
  EXPECT_EQ(frame_7("vel.vdb"), "vel.vdb");  // no field: one file for all time
  FrameField field;
  ASSERT_TRUE(read_frame_field("f_###.obj", field));
  EXPECT_EQ(with_frame_number("f_###.obj", field, -1), "f_-01.obj");  // as Houdini's $F3
  EXPECT_EQ(with_frame_number("f_###.obj", field, 12345), "f_12345.obj");
  EXPECT_EQ(frame_7(std::string(18, '#')), std::string(17, '0') + "7");
}

TEST(FrameField, ANameWithoutOneReadableFieldIsRefused) {
  for (const char* name : {"a.####.b.#.vdb", "a.#.%d.vdb", "a.%d.%d.vdb", "a.%s.vdb", "a.%4d.vdb", "a.%0d.vdb",
                           "a.%019d.vdb", "a.%0123456789012345678901d.vdb", "a.%", "a.%0"})
    EXPECT_EQ(frame_7(name), "refused") << name;
  EXPECT_EQ(frame_7(std::string(19, '#')), "refused");
  EXPECT_EQ(frame_7("a.%018d"), std::string("a.") + std::string(17, '0') + "7");
}

}  // namespace
}  // namespace treeanim
