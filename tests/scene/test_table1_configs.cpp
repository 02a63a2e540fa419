// configs/table1-*.json: the paper's Table 1 model sizes (clusters / particles) within 5%.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "lsystem/lsystem.h"
#include "scene/lsystem_section.h"
#include "scene/tree_section.h"
#include "tree/build_tree_model.h"

namespace treeanim {
namespace {

struct Table1Row {
  const char* name;
  size_t clusters;
  size_t particles;
  bool leaves;
};

// configs/<name>.json (its /lsystem and /tree sections) => the model.
TreeModel build_config(const std::string& name) {
  const std::filesystem::path file = std::filesystem::path(TREEANIM_SOURCE_DIR) / "configs" / (name + ".json");
  std::ifstream in(file);
  EXPECT_TRUE(in) << file;
  Json document = Json::parse(in);
  SceneReader reader(document, file.parent_path(), file.string());
  const LsystemOptions lsystem = read_lsystem_options(reader.root().object("lsystem"), 1);
  const TreeOptions tree = read_tree_options(reader.root().object("tree"));
  GrowthStats stats;
  return build_tree_model(grow_skeleton(lsystem, &stats), tree);
}

TEST(Table1Configs, CountsAreWithinFivePercentOfThePaper) {
  const Table1Row rows[] = {{"table1-300", 5, 300, false},        {"table1-900", 15, 900, false},
                            {"table1-13548", 293, 13548, true},   {"table1-38772", 867, 38772, true},
                            {"table1-99816", 2230, 99816, true},  {"table1-211812", 4975, 211812, true}};
  for (const Table1Row& row : rows) {
    const TreeModel m = build_config(row.name);
    EXPECT_NEAR(double(m.vertex_count()), double(row.particles), 0.05 * double(row.particles)) << row.name;
    EXPECT_NEAR(double(m.cluster_count()), double(row.clusters), 0.05 * double(row.clusters)) << row.name;
    EXPECT_EQ(m.leaf_count() > 0, row.leaves) << row.name;
  }
}

}  // namespace
}  // namespace treeanim
