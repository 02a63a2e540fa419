// The writers' half of the format table: a sink and its targets for every row, none for another name.
#include <gtest/gtest.h>

#include "formats/sink_factories.h"
#include "output/output_formats.h"

namespace treeanim {
namespace {

TEST(SinkFactories, EveryFormatOfTheTableHasASink) {
  for (const OutputFormatRow& row : output_formats()) {
    EXPECT_NE(find_sink_factory(row.name), nullptr) << row.name;
    EXPECT_NE(find_sink_targets(row.name), nullptr) << row.name;
  }
  EXPECT_EQ(find_sink_factory("hdf"), nullptr);
  EXPECT_EQ(find_sink_targets("hdf"), nullptr);
}

}  // namespace
}  // namespace treeanim
