// The table of output formats: well-formed rows, and docs/outputs.md and docs/design.md list
// exactly its formats.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "output/output_estimate.h"
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

TEST(OutputFormats, SizeEstimatesPerFormat) {
  // 100 vertices, 50 triangles, 7 clusters, 10 frames written every 3rd: 4 frames of 1200 bytes of vectors.
  auto bytes = [](const char* format, auto&& set) {
    OutputOptions o;
    o.format = find_output_format(format);
    o.frame_step = 3;
    set(o);
    return estimated_output_bytes(o, 100, 50, 7, 10);
  };
  auto plain = [](OutputOptions&) {};
  auto with_normals = [](OutputOptions& o) { o.normals = true; };
  EXPECT_EQ(bytes("hdf5", plain), 4800);
  EXPECT_EQ(bytes("hdf5", [](OutputOptions& o) { o.quantize = 1e-3, o.velocities = o.normals = true; }), 12000);
  EXPECT_EQ(bytes("obj", plain), 17600);
  EXPECT_EQ(bytes("obj", with_normals), 32000);
  EXPECT_EQ(bytes("gltf", plain), 7200);
  for (const char* format : {"glb", "pc2", "mdd"}) EXPECT_EQ(bytes(format, with_normals), 9600) << format;
  EXPECT_EQ(bytes("vat", plain), 12800);
  EXPECT_EQ(bytes("vat", [](OutputOptions& o) { o.vat_half = true; }), 6400);
  EXPECT_EQ(bytes("skinned_glb", plain), 4 * 28 * 7);  // a joint per cluster
  EXPECT_EQ(bytes("skinned_glb", [](OutputOptions& o) { o.max_joints = 5; }), 4 * 28 * 5);
  EXPECT_EQ(bytes("usd", plain), 4 * 36 * 100);
  EXPECT_EQ(bytes("usd", with_normals), 4 * (36 + 38) * 100);
  EXPECT_EQ(bytes("usd", [](OutputOptions& o) { o.skinned = true; }), 4 * 96 * 7);
}

}  // namespace
}  // namespace treeanim
