// The table of output formats: well-formed rows, and docs/outputs.md and docs/design.md list
// exactly its formats.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "output/output_formats.h"

namespace treeanim {
namespace {

// The format names of a doc's list between "<!-- formats: begin -->" and
// "<!-- formats: end -->": the first `quoted` word of each "- " line.
std::vector<std::string> documented_formats(const std::string& doc) {
  std::ifstream in(std::filesystem::path(TREEANIM_SOURCE_DIR) / "docs" / doc);
  EXPECT_TRUE(in) << doc;
  std::vector<std::string> names;
  bool inside = false;
  for (std::string line; std::getline(in, line);) {
    if (line == "<!-- formats: begin -->") inside = true;
    else if (line == "<!-- formats: end -->") inside = false;
    else if (inside && line.rfind("- `", 0) == 0) names.push_back(line.substr(3, line.find('`', 3) - 3));
    else if (inside && !line.empty()) ADD_FAILURE() << doc << ": not a format line: " << line;
  }
  EXPECT_FALSE(inside) << doc << ": no \"<!-- formats: end -->\"";
  return names;
}

TEST(OutputFormats, DocsListEveryFormatOfTheTableAndNothingElse) {
  std::vector<std::string> table;
  for (const OutputFormatRow& row : output_formats()) table.emplace_back(row.name);
  for (const char* doc : {"outputs.md", "design.md"}) EXPECT_EQ(documented_formats(doc), table) << doc;
}

TEST(OutputFormats, RowsAreComplete) {
  std::set<std::string> names;
  for (const OutputFormatRow& row : output_formats()) {
    SCOPED_TRACE(row.name);
    EXPECT_TRUE(names.insert(row.name).second) << "a second row of the same name";
    EXPECT_EQ(find_output_format(row.name), &row);
    EXPECT_NE(row.frame_bytes, nullptr);
    // The keys every element takes are read before the format's own; none may come twice.
    std::set<std::string> keys = {"format", "path", "frame_step"};
    for (const OutputKey& key : row.keys) {
      EXPECT_TRUE(keys.insert(key.name).second) << key.name;
      EXPECT_NE(key.store, nullptr) << key.name;
      if (key.type == OutputKey::Type::kChoice) {
        EXPECT_LT(size_t(key.fallback), key.choices.size()) << key.name;
      }
      if (key.type == OutputKey::Type::kInteger || key.type == OutputKey::Type::kNumber) {
        EXPECT_TRUE(key.optional || (key.lo <= key.fallback && key.fallback <= key.hi)) << key.name;
      }
    }
  }
  EXPECT_EQ(find_output_format("hdf"), nullptr);
}

}  // namespace
}  // namespace treeanim
