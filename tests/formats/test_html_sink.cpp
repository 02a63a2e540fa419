// The preview page parsed back: its embedded JSON holds the rest mesh with bark triangles
// first, every pushed frame (float32, or int16 within half its vertex's step when reduced), the plots'
// displacements and wind; the viewer bundle follows; a page too small is refused. The forest
// page composes tree pages: placed, the first tree's wind turned into the forest, displacements
// over all trees, frames thinned alike when the pages together pass the limit.
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

#include "common/errors.h"
#include "formats/base64.h"
#include "formats/html_forest.h"
#include "formats/preview_page.h"
#include "files/text_output.h"
#include "output/output_options.h"
#include "formats_test_support.h"

namespace treeanim {
namespace {

using test::small_frame;
using test::small_info;
using test::small_model;

class HtmlSink : public test::TempFolder {};

std::string unbase64(const std::string& text) {
  static const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  uint32_t bits = 0;
  int count = 0;
  for (char c : text) {
    if (c == '=') break;
    bits = (bits << 6) | uint32_t(digits.find(c));
    if ((count += 6) >= 8) out += char((bits >> (count -= 8)) & 0xFF);
  }
  return out;
}

template <typename T>
std::vector<T> array_of(const nlohmann::json& text) {
  const std::string bytes = unbase64(text.get<std::string>());
  std::vector<T> values(bytes.size() / sizeof(T));
  std::memcpy(values.data(), bytes.data(), values.size() * sizeof(T));
  return values;
}

// The page => its embedded bake, after checking the page's frame around it.
nlohmann::json page_data(const std::filesystem::path& path) {
  const std::string page = test::read_file(path);
  const std::string open = "<script id=\"treeanim-bake\" type=\"application/json\">";
  const size_t begin = page.find(open);
  EXPECT_EQ(page.rfind("<!doctype html>", 0), 0u);
  EXPECT_NE(begin, std::string::npos);
  const size_t end = page.find("</script>", begin);
  EXPECT_NE(page.find("<script>", end), std::string::npos) << "the viewer follows the data";
  return nlohmann::json::parse(page.substr(begin + open.size(), end - begin - open.size()));
}

TEST(Base64, EncodesEveryPaddingCase) {
  EXPECT_EQ(base64("", 0), "");
  EXPECT_EQ(base64("f", 1), "Zg==");
  EXPECT_EQ(base64("fo", 2), "Zm8=");
  EXPECT_EQ(base64("foo", 3), "Zm9v");
  EXPECT_EQ(base64("foobar", 6), "Zm9vYmFy");
}

TEST_F(HtmlSink, PageHoldsMeshFramesAndPlots) {
  const TreeModel m = small_model();
  test::bake({test::output("html", "tree")}, dir_, m, small_info(5, 1));
  EXPECT_EQ(entries(), std::vector<std::string>{"tree.html"});
  const nlohmann::json data = page_data(dir_ / "tree.html");
  EXPECT_EQ(data["format"], "treeanim-preview");
  EXPECT_EQ(data["reduced"], "");
  const nlohmann::json& tree = data["trees"][0];
  EXPECT_EQ(array_of<float>(tree["rest"]), test::rest_f32(m));
  // (1,2,0) and (0,2,3) are bark (vertex 3, the leaf's attachment, alone does not make a leaf).
  EXPECT_EQ(tree["bark_triangles"], 2);
  EXPECT_EQ(array_of<uint32_t>(tree["triangles"]), m.triangles);
  EXPECT_EQ(tree["frames"]["encoding"], "float32");
  EXPECT_EQ(tree["frames"]["sample"], (std::vector<int>{0, 1, 2, 3, 4}));
  std::vector<float> pushed;
  for (long long f = 1; f <= 5; ++f) {
    const std::vector<float> p = small_frame(m, f).positions;
    pushed.insert(pushed.end(), p.begin(), p.end());
  }
  EXPECT_EQ(array_of<float>(tree["frames"]["data"]), pushed);
  EXPECT_EQ(data["plot"]["frame"], (std::vector<int>{1, 2, 3, 4, 5}));
  EXPECT_DOUBLE_EQ(data["plot"]["time"][2].get<double>(), 3.0 / 24.0);
  // Frame 5 sways each free vertex by 0.013 * 5 * (1, 2, 3) / 7; two of six are anchored.
  const double sway = 0.013 * 5 / 7 * std::sqrt(14.0);
  EXPECT_NEAR(data["plot"]["max_displacement"][4].get<double>(), sway, 1e-6);
  EXPECT_NEAR(data["plot"]["rms_displacement"][4].get<double>(), sway * std::sqrt(4.0 / 6.0), 1e-6);
  EXPECT_EQ(data["plot"]["wind"], std::vector<double>(15, 0.0)) << "no wind keys: calm air";
}

TEST_F(HtmlSink, LargeBakeIsReducedToFit) {
  // 3000 vertices, 1200 frames: 57.6 MB as float32 in base64, 28.8 MB as int16, above a 16 MiB page.
  TreeModel m = small_model();
  const long V = 3000;
  m.rest_positions = Eigen::Matrix3Xd::Random(3, V);
  m.vertex_leaf.assign(size_t(V), -1);
  m.vertex_anchored.assign(size_t(V), 0);
  m.triangles = {0, 1, 2};
  OutputOptions options = test::output("html", "big.html");
  options.max_page_bytes = 16 << 20;
  BakeInfo info = small_info(1200, 0);
  test::bake({options}, dir_, m, info);
  const auto bytes = std::filesystem::file_size(dir_ / "big.html");
  EXPECT_LE(bytes, options.max_page_bytes);
  const nlohmann::json data = page_data(dir_ / "big.html");
  const nlohmann::json& frames = data["trees"][0]["frames"];
  EXPECT_EQ(frames["encoding"], "int16");
  const auto sample = frames["sample"].get<std::vector<long long>>();
  EXPECT_EQ(sample.front(), 0);
  EXPECT_EQ(sample.back(), 1199) << "the last frame is always kept";
  EXPECT_EQ(sample.size(), 601u) << "every 2nd frame, and the last";
  EXPECT_EQ(sample[1], 2);
  EXPECT_EQ(data["plot"]["time"].size(), 1200u) << "the plots keep every frame";
  const std::vector<float> step = array_of<float>(frames["step"]);
  ASSERT_EQ(step.size(), size_t(V));
  const std::vector<int16_t> q = array_of<int16_t>(frames["data"]);
  ASSERT_EQ(q.size(), sample.size() * size_t(V) * 3);
  const std::vector<float> rest = test::rest_f32(m);
  const size_t k = sample.size() / 2;
  const std::vector<float> pushed = small_frame(m, sample[k]).positions;
  for (size_t i = 0; i < size_t(V) * 3; ++i)
    ASSERT_NEAR(rest[i] + q[k * size_t(V) * 3 + i] * step[i / 3], pushed[i], 0.5 * step[i / 3] + 1e-6) << i;
  const std::string note = data["reduced"];
  EXPECT_EQ(note.rfind("Reduced to fit 16 MiB: positions quantized (steps ", 0), 0u) << note;
  EXPECT_NE(note.find("; 1 frame in "), std::string::npos) << note;
}

TEST_F(HtmlSink, PageTooSmallForTheTreeIsRefused) {
  TreeModel m = small_model();
  m.rest_positions = Eigen::Matrix3Xd::Random(3, 200000);
  m.vertex_leaf.assign(200000, -1);
  m.vertex_anchored.assign(200000, 0);
  OutputOptions options = test::output("html", "big.html");
  options.max_page_bytes = 2 << 20;
  try {
    OutputSet set({options}, dir_, m, small_info(5, 1));
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "/outputs/0/max_mib: the page needs 7 MiB at least for this tree (viewer, mesh and two frames)");
  }
}

// Two tree pages of the small model, 5 frames: the second's displacements doubled, the first's
// wind (1, 0, 0) m/s in its own frame.
std::vector<ForestPageTree> two_tree_pages(const std::filesystem::path& dir) {
  test::bake({test::output("html", "a")}, dir, small_model(), small_info(5, 1));
  nlohmann::json a = page_data(dir / "a.html");
  nlohmann::json b = a;
  for (size_t i = 0; i < 5; ++i) {
    a["plot"]["wind"][3 * i] = 1.0;
    b["plot"]["max_displacement"][i] = 2 * a["plot"]["max_displacement"][i].get<double>();
    b["plot"]["rms_displacement"][i] = 2 * a["plot"]["rms_displacement"][i].get<double>();
  }
  write_text_output(dir / "a.html", preview_page_text("a", a));
  write_text_output(dir / "b.html", preview_page_text("b", b));
  return {{"a", dir / "a.html", Eigen::Vector3d(1, 0, 2), 90}, {"b", dir / "b.html", Eigen::Vector3d::Zero(), 0}};
}

TEST_F(HtmlSink, ForestPagePlacesTreesAndCombinesPlots) {
  const auto trees = two_tree_pages(dir_);
  const nlohmann::json a = page_data(dir_ / "a.html"), b = page_data(dir_ / "b.html");
  write_forest_page(dir_ / "forest.html", trees, 64 << 20);
  const nlohmann::json data = page_data(dir_ / "forest.html");
  EXPECT_EQ(data["title"], "forest (treeanim test)");
  EXPECT_EQ(data["reduced"], "");
  ASSERT_EQ(data["trees"].size(), 2u);
  EXPECT_EQ(data["trees"][0]["position"], (std::vector<double>{1, 0, 2}));
  EXPECT_EQ(data["trees"][0]["rotation"], 90.0);
  EXPECT_EQ(data["trees"][1]["position"], (std::vector<double>{0, 0, 0}));
  EXPECT_EQ(data["trees"][0]["frames"], a["trees"][0]["frames"]) << "the frames as the tree's page holds them";
  EXPECT_EQ(data["trees"][0]["rest"], a["trees"][0]["rest"]) << "in the tree's frame, placed by the viewer";
  // +x in the first tree's frame is -z in the forest's once it is turned by 90 degrees about +Y.
  EXPECT_EQ(data["plot"]["wind"][0], 0.0);
  EXPECT_EQ(data["plot"]["wind"][2], -1.0);
  const double r = a["plot"]["rms_displacement"][4].get<double>();
  EXPECT_EQ(data["plot"]["max_displacement"][4], b["plot"]["max_displacement"][4]);
  EXPECT_NEAR(data["plot"]["rms_displacement"][4].get<double>(), std::sqrt((r * r + 4 * r * r) / 2), 1e-12);
  EXPECT_EQ(data["plot"]["time"], a["plot"]["time"]);
}

TEST_F(HtmlSink, ForestPageThinsFramesToFit) {
  const auto trees = two_tree_pages(dir_);
  const nlohmann::json a = page_data(dir_ / "a.html");
  const size_t whole = forest_page(trees, "forest", 64 << 20).size();
  const std::string text = forest_page(trees, "forest", whole - 1);
  EXPECT_LE(text.size(), whole - 1);
  const nlohmann::json data = preview_page_data(text, "forest.html");
  const std::string frames = a["trees"][0]["frames"]["data"];
  const size_t one = frames.size() / 5;
  for (const nlohmann::json& tree : data["trees"]) {
    EXPECT_EQ(tree["frames"]["sample"], (std::vector<int>{0, 2, 4}));
    EXPECT_EQ(tree["frames"]["data"],
              frames.substr(0, one) + frames.substr(2 * one, one) + frames.substr(4 * one, one));
  }
  // A limit of 0.6 MiB, rounded as every limit of whole MiB prints.
  EXPECT_EQ(data["reduced"], "Reduced to fit 1 MiB: 1 frame in 2 of the trees' pages kept, the others interpolated.");
  try {
    forest_page(trees, "forest", 1000);
    FAIL() << "accepted";
  } catch (const OutputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("forest.html: the 2 trees' meshes and two frames each take 1 MiB, above the "
                                          "page's limit of 0 MiB (max_mib)", 0), 0u) << e.what();
  }
}

TEST_F(HtmlSink, ForestPageNamesAPageThatIsNotOne) {
  auto trees = two_tree_pages(dir_);
  write_text_output(dir_ / "b.html", "<!doctype html>\n");
  try {
    forest_page(trees, "forest", 64 << 20);
    FAIL() << "accepted";
  } catch (const OutputError& e) {
    EXPECT_EQ(std::string(e.what()),
              (dir_ / "b.html").string() + ": not a treeanim preview page (no <script id=\"treeanim-bake\"> element)");
  }
}

}  // namespace
}  // namespace treeanim
