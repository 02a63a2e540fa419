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
#include "formats/output_estimate.h"
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

// A name the page shows, in its title and in its data, changes no element's end: "<!--<script"
// in the data's text would make the browser read the viewer as part of the data.
TEST(PreviewPage, NamesWithMarkupStayText) {
  const std::string name = "a&b<!--<script>";
  const nlohmann::json data = {{"format", "treeanim-preview"}, {"title", name}};
  const std::string page = preview_page_text(name, data);
  EXPECT_NE(page.find("<title>a&amp;b&lt;!--&lt;script></title>"), std::string::npos);
  const size_t open = page.find("<script id=\"treeanim-bake\"");
  EXPECT_EQ(page.find("<!--"), std::string::npos);
  EXPECT_EQ(page.find("<script", open + 1), page.find("<script>", open)) << "no '<script' inside the data";
  EXPECT_EQ(preview_page_data(page, "a.html")["title"], name);
  EXPECT_EQ(preview_page_size(name, data), page.size());
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

// A model of `vertices` vertices and `triangles` triangles (every third one leaf): what sizes a
// page, without the grower.
TreeModel sized_model(size_t vertices, size_t triangles) {
  TreeModel m = small_model();
  m.rest_positions = Eigen::Matrix3Xd::Random(3, Eigen::Index(vertices));
  m.vertex_leaf.assign(vertices, -1);
  m.vertex_anchored.assign(vertices, 0);
  m.triangles.resize(3 * triangles);
  for (size_t i = 0; i < m.triangles.size(); ++i) m.triangles[i] = uint32_t(i % vertices);
  m.triangle_material.resize(triangles);
  for (size_t t = 0; t < triangles; ++t) m.triangle_material[t] = t % 3 == 2 ? kMaterialLeaf : kMaterialBark;
  return m;
}

// Vertices and triangles of the trees the page is swept over (`treeanim info`, 2026-11-28).
struct TreeSize {
  const char* name;
  size_t vertices, triangles;
};
constexpr TreeSize kDemo{"demo", 9797, 11772}, kTable38772{"table1-38772", 38578, 71158},
    kTable211812{"table1-211812", 211864, 404284};

// The html output `name` of at most `mib` MiB.
OutputOptions page_output(const std::string& name, size_t mib) {
  OutputOptions options = test::output("html", name);
  options.max_page_bytes = mib << 20;
  return options;
}

TEST(PagePlan, TakesTheFirstEncodingThatFitsAndTheSmallestStride) {
  PreviewPageShape shape;
  shape.vertices = 1000;
  shape.triangles = 1500;
  shape.frame_number_chars = 4;
  shape.skeleton = {700000, 700040};
  const size_t limit = 4 << 20;
  size_t last_stride = 1;
  for (size_t frames : {0, 1, 2, 3, 10, 100, 190, 200, 300, 400, 1000, 2000, 5000}) {
    shape.frames = frames;
    const PreviewPagePlan plan = plan_preview_page(shape, limit);
    ASSERT_TRUE(plan.fits) << frames;
    EXPECT_LE(plan.bytes, double(limit)) << frames;
    EXPECT_EQ(plan.bytes, preview_page_bytes(shape, plan.quantized, plan.stride));
    if (plan.quantized) {
      EXPECT_GT(preview_page_bytes(shape, false, 1), double(limit)) << "float32 fits: " << frames;
    }
    if (plan.stride > 1) {
      EXPECT_GT(preview_page_bytes(shape, true, plan.stride - 1), double(limit)) << frames;
    }
    EXPECT_GE(plan.stride, last_stride) << "more frames never keep a finer stride";
    last_stride = plan.stride;
  }
  // Two frames as int16 are the least a page keeps.
  shape.frames = 2;
  const double fewest = preview_page_bytes(shape, true, 1);
  EXPECT_FALSE(plan_preview_page(shape, size_t(fewest) - 1).fits);
  EXPECT_TRUE(plan_preview_page(shape, size_t(fewest)).fits);
  shape.frames = 1000;
  EXPECT_EQ(plan_preview_page(shape, size_t(fewest) - 1).bytes, preview_page_bytes(shape, true, 999));
}

TEST(PagePlan, KeptFramesAreEveryStrideThAndTheLast) {
  EXPECT_EQ(kept_frames(0, 3), std::vector<size_t>{});
  EXPECT_EQ(kept_frames(1, 3), std::vector<size_t>{0});
  EXPECT_EQ(kept_frames(7, 3), (std::vector<size_t>{0, 3, 6}));
  EXPECT_EQ(kept_frames(8, 3), (std::vector<size_t>{0, 3, 6, 7}));
  for (size_t count = 0; count < 60; ++count)
    for (size_t stride = 1; stride < 62; ++stride)
      ASSERT_EQ(kept_frame_count(count, stride), kept_frames(count, stride).size()) << count << " " << stride;
}

TEST(PagePlan, FurtherStrideDropsEnoughFrames) {
  // 25 kept frames of 100 characters: 250 characters too many drop 3 frames at least.
  const size_t k = further_stride(25, 100, 250);
  EXPECT_GE(25 - kept_frame_count(25, k), 3u);
  EXPECT_LT(25 - kept_frame_count(25, k - 1), 3u);
  EXPECT_EQ(further_stride(25, 100, 2300), 24u) << "down to the first and the last";
  EXPECT_EQ(further_stride(25, 100, 2301), 0u) << "not even those";
  EXPECT_EQ(further_stride(2, 100, 1), 0u);
}

// Every frame count from 2 to 1,000 of the demo and the two largest trees of the paper's Table 1
// at 64 MiB: each plan fits, keeps the most it can, and a page of every tree is written at the
// counts where its plan changes (the largest page of the sweep is printed).
TEST_F(HtmlSink, PlanSweepOfTheTablesTreesAt64MiB) {
  const OutputOptions options = page_output("page.html", 64);
  double largest = 0;
  std::string largest_at;
  for (const TreeSize& tree : {kDemo, kTable38772, kTable211812}) {
    const TreeModel m = sized_model(tree.vertices, tree.triangles);
    PreviewPagePlan last;
    std::vector<long long> changes;
    for (long long frames = 2; frames <= 1000; ++frames) {
      const PreviewPageShape shape = html_page_shape(options, m, small_info(frames, 0));
      const PreviewPagePlan plan = plan_preview_page(shape, options.max_page_bytes);
      ASSERT_TRUE(plan.fits) << tree.name << " " << frames;
      ASSERT_LE(plan.bytes, double(options.max_page_bytes)) << tree.name << " " << frames;
      if (plan.stride > 1) {
        ASSERT_GT(preview_page_bytes(shape, true, plan.stride - 1), double(options.max_page_bytes));
      }
      if (plan.bytes > largest) {
        largest = plan.bytes;
        largest_at = std::string(tree.name) + ", " + std::to_string(frames) + " frames";
      }
      if (frames > 2 && (plan.quantized != last.quantized || plan.stride != last.stride)) changes.push_back(frames);
      last = plan;
    }
    EXPECT_FALSE(changes.empty()) << tree.name << ": the sweep passes no limit";
    std::printf("%s: the plan changes at frames", tree.name);
    for (long long f : changes) std::printf(" %lld", f);
    std::printf("\n");
  }
  std::printf("largest planned page of the sweep: %.0f bytes (%s), limit %zu\n", largest, largest_at.c_str(),
              options.max_page_bytes);
}

// Pages written at the limit: each within its plan, within its limit, and near it when thinned
// (it keeps the most frames that fit). Small trees and small limits, so the writes are quick.
TEST_F(HtmlSink, PagesStayWithinTheirPlan) {
  struct Case {
    size_t vertices, triangles;
    long long frames;
    size_t mib;
  };
  const std::vector<Case> cases = {{300, 400, 1, 1},      {300, 400, 2, 1},      {300, 400, 3, 1},
                                   {300, 400, 40, 1},     {300, 400, 90, 1},     {300, 400, 200, 1},
                                   {300, 400, 1000, 1},   {2000, 3000, 2, 1},    {2000, 3000, 5, 1},
                                   {2000, 3000, 14, 2},   {2000, 3000, 60, 2},   {2000, 3000, 61, 2},
                                   {2000, 3000, 300, 2},  {2000, 3000, 1000, 2}, {9797, 11772, 2, 2},
                                   {9797, 11772, 9, 2},   {9797, 11772, 1000, 2}};
  for (const Case& c : cases) {
    const TreeModel m = sized_model(c.vertices, c.triangles);
    const OutputOptions options = page_output("page.html", c.mib);
    const BakeInfo info = small_info(c.frames, 0);
    const PreviewPagePlan plan = plan_preview_page(html_page_shape(options, m, info), options.max_page_bytes);
    ASSERT_TRUE(plan.fits);
    test::bake({options}, dir_, m, info);
    const double bytes = double(std::filesystem::file_size(dir_ / "page.html"));
    const std::string at = std::to_string(c.vertices) + " vertices, " + std::to_string(c.frames) + " frames";
    EXPECT_LE(bytes, plan.bytes) << at;
    EXPECT_LE(bytes, double(options.max_page_bytes)) << at;
    EXPECT_LE(bytes, estimated_output_bytes(options, c.vertices, c.triangles, 7, c.frames)) << at;
    // What the plan leaves unused: the plots' numbers below their longest, the note's room.
    EXPECT_LT(plan.bytes - bytes, 150.0 * double(c.frames) + 2048) << at;
    const nlohmann::json frames = page_data(dir_ / "page.html")["trees"][0]["frames"];
    EXPECT_EQ(frames["encoding"], plan.quantized ? "int16" : "float32") << at;
    EXPECT_EQ(frames["sample"].size(), kept_frame_count(size_t(c.frames), plan.stride)) << at;
    if (plan.stride > 1) {  // the frames a finer stride keeps besides would not have fitted
      const size_t more = kept_frame_count(size_t(c.frames), plan.stride - 1) - frames["sample"].size();
      EXPECT_GT(bytes + double(more * base64_chars(6 * c.vertices)) + 150.0 * double(c.frames) + 2048,
                double(options.max_page_bytes)) << at;
    }
  }
}

// The page of the bake that overran its limit in the field (table1-211812, 96 frames, 67.5 MB at
// 64 MiB), the largest page of the sweep above (table1-38772, 417 frames, planned within 3.5 kB
// of 64 MiB) and the demo's largest float32 page: each written, within its plan and 64 MiB.
TEST_F(HtmlSink, PagesOfTheTablesTreesFit64MiB) {
  const OutputOptions options = page_output("page.html", 64);
  for (const auto& [tree, frames] :
       {std::pair{kTable211812, 96LL}, std::pair{kTable38772, 417LL}, std::pair{kDemo, 421LL}}) {
    const TreeModel m = sized_model(tree.vertices, tree.triangles);
    const BakeInfo info = small_info(frames, 0);
    const PreviewPagePlan plan = plan_preview_page(html_page_shape(options, m, info), options.max_page_bytes);
    test::bake({options}, dir_, m, info);
    const double bytes = double(std::filesystem::file_size(dir_ / "page.html"));
    EXPECT_LE(bytes, plan.bytes) << tree.name << " " << frames;
    EXPECT_LE(bytes, double(64 << 20)) << tree.name << " " << frames;
    std::printf("%s, %lld frames: %.0f bytes (%s, stride %zu), limit %zu\n", tree.name, frames, bytes,
                plan.quantized ? "int16" : "float32", plan.stride, options.max_page_bytes);
  }
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
              "/outputs/0/max_mib: the page needs 8 MiB at least for this tree (viewer, mesh, two frames and the "
              "plots of its 5 written frames), more than max_mib = 2: raise max_mib where its range allows, raise "
              "frame_step or shorten the bake (the plots keep every written frame), or leave the html output out");
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
  // Only pages written for another limit can leave no room for the first tree.
  try {
    forest_page(trees, "forest", 1000);
    FAIL() << "accepted";
  } catch (const OutputError& e) {
    EXPECT_EQ(std::string(e.what()), "forest.html: tree a's mesh and two frames alone take 1 MiB, above the page's "
                                     "limit of 0 MiB (max_mib): its page was not written for this limit");
  }
}

// Trees in the forest page at `limit`, or 0 when it refuses.
size_t trees_shown(const std::vector<ForestPageTree>& trees, size_t limit) {
  try {
    return preview_page_data(forest_page(trees, "forest", limit), "forest.html")["trees"].size();
  } catch (const OutputError&) {
    return 0;
  }
}

TEST_F(HtmlSink, ForestPageLeavesOutTreesThatDoNotFitWithTwoFramesEach) {
  const auto trees = two_tree_pages(dir_);
  // The smallest limit that shows both trees, and one byte less.
  size_t one = 0, both = forest_page(trees, "forest", 64 << 20).size();
  while (both - one > 1) {
    const size_t mid = one + (both - one) / 2;
    (trees_shown(trees, mid) == 2 ? both : one) = mid;
  }
  nlohmann::json data = preview_page_data(forest_page(trees, "forest", both), "forest.html");
  for (const nlohmann::json& tree : data["trees"]) EXPECT_EQ(tree["frames"]["sample"], (std::vector<int>{0, 4}));
  EXPECT_EQ(data["reduced"], "Reduced to fit 1 MiB: 1 frame in 4 of the trees' pages kept, the others interpolated.");
  const std::string text = forest_page(trees, "forest", one);
  EXPECT_LE(text.size(), one);
  data = preview_page_data(text, "forest.html");
  ASSERT_EQ(data["trees"].size(), 1u);
  EXPECT_EQ(data["trees"][0]["position"], (std::vector<double>{1, 0, 2})) << "the first tree";
  EXPECT_EQ(data["trees"][0]["frames"]["sample"], (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(data["reduced"], "Reduced to fit 1 MiB: the first 1 of 2 trees shown, the others left out.");
  EXPECT_EQ(data["plot"]["max_displacement"], page_data(dir_ / "b.html")["plot"]["max_displacement"])
      << "the plots still cover every tree";
}

// A tree's page at its limit leaves room for the forest page of that tree alone, placed with
// the longest numbers and named longer than the tree's page, its note quoted.
TEST_F(HtmlSink, ForestPageOfATreePageAtItsLimitFits) {
  const TreeModel m = sized_model(2000, 3000);
  test::bake({page_output("t.html", 1)}, dir_, m, small_info(1000, 0));
  const std::vector<ForestPageTree> trees = {
      {"a-tree-id-of-sixty-four-characters-which-is-the-longest-allowed.", dir_ / "t.html",
       Eigen::Vector3d(-9876.123456789012, 0.1234567890123456, -1234.567890123456), -123.45678901234567}};
  const std::string text = forest_page(trees, "forest", 1 << 20);
  EXPECT_LE(text.size(), size_t(1 << 20));
  const nlohmann::json data = preview_page_data(text, "forest.html");
  ASSERT_EQ(data["trees"].size(), 1u);
  EXPECT_EQ(data["trees"][0]["frames"], page_data(dir_ / "t.html")["trees"][0]["frames"]) << "nothing thinned";
  EXPECT_NE(data["reduced"].get<std::string>().find("1 of 1 tree pages were reduced; tree a-tree-id"),
            std::string::npos) << data["reduced"];
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
