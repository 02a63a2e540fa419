#include "formats/html_forest.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/errors.h"
#include "common/read_text_file.h"
#include "formats/preview_page.h"
#include "files/text_output.h"
#include "tree/tree_placement.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

using nlohmann::json;

Eigen::Vector3d vector_of(const json& v) { return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()}; }

// A tree's page => its bake, checked to plot the same frames as the first tree's.
json tree_page_data(const ForestPageTree& tree, const json* first) {
  std::string text, reason;
  if (!read_text_file(tree.page, text, reason))
    throw OutputError(tree.page.string() + ": tree " + tree.id + "'s preview page cannot be read (" + reason + ")");
  json data = preview_page_data(text, tree.page.string());
  if (first && data.at("plot").at("time") != first->at("plot").at("time"))
    throw OutputError(tree.page.string() + ": tree " + tree.id + "'s page plots other frames than " +
                      "the first tree's");
  return data;
}

// Vertices of a tree of the page: its rest positions are float32 x y z, 16 base64 characters.
double vertex_count(const json& tree) { return double(tree.at("rest").get_ref<const std::string&>().size()) / 16.0; }

// Base64 characters of one kept frame: a frame is 12 or 6 bytes a vertex, a multiple of 3, so
// each frame is a run of whole characters and frames can be dropped from the text as it is.
size_t frame_chars(const json& tree) {
  return tree.at("frames").at("data").get_ref<const std::string&>().size() /
         std::max<size_t>(1, tree.at("frames").at("sample").size());
}

// Kept frames, stride => the ones still kept: 0, stride, 2 stride, ..., and the last.
std::vector<size_t> thinned(size_t kept, size_t stride) {
  std::vector<size_t> out;
  for (size_t j = 0; j < kept; j += stride) out.push_back(j);
  if (kept > 0 && out.back() != kept - 1) out.push_back(kept - 1);
  return out;
}

// Base64 characters the trees' frames take when thinned by `stride`.
double thinned_chars(const json& trees, size_t stride) {
  double chars = 0;
  for (const json& tree : trees)
    chars += double(thinned(tree.at("frames").at("sample").size(), stride).size()) * double(frame_chars(tree));
  return chars;
}

void thin(json& tree, size_t stride) {
  json& frames = tree.at("frames");
  const std::string& data = frames.at("data").get_ref<const std::string&>();
  const size_t chars = frame_chars(tree);
  json sample = json::array();
  std::string kept;
  for (size_t j : thinned(frames.at("sample").size(), stride)) {
    sample.push_back(frames.at("sample")[j]);
    kept.append(data, j * chars, chars);
  }
  frames["sample"] = std::move(sample);
  frames["data"] = std::move(kept);
}

// What the trees' own pages reduced, in a sentence; "" when none did.
std::string tree_reductions(const std::vector<ForestPageTree>& trees, const std::vector<std::string>& notes) {
  const auto first = std::find_if(notes.begin(), notes.end(), [](const std::string& n) { return !n.empty(); });
  if (first == notes.end()) return "";
  const long long count = std::count_if(notes.begin(), notes.end(), [](const std::string& n) { return !n.empty(); });
  return std::to_string(count) + " of " + std::to_string(notes.size()) + " tree pages were reduced; tree " +
         trees[size_t(first - notes.begin())].id + "'s says: " + *first;
}

}  // namespace

std::string forest_page(const std::vector<ForestPageTree>& trees, const std::string& name, size_t max_page_bytes) {
  json page = tree_page_data(trees.at(0), nullptr);
  const size_t frames = page.at("plot").at("time").size();
  const TreePlacement first = make_tree_placement(trees[0].translation, trees[0].rotation_degrees);
  // The wind at the first tree, turned from its frame into the forest's.
  json wind = json::array();
  const json& tree_wind = page.at("plot").at("wind");
  for (size_t i = 0; i < frames; ++i) {
    const Eigen::Vector3d w = first.rotation * Eigen::Vector3d(tree_wind[3 * i].get<double>(),
                                                               tree_wind[3 * i + 1].get<double>(),
                                                               tree_wind[3 * i + 2].get<double>());
    for (int k = 0; k < 3; ++k) wind.push_back(w[k]);
  }
  const Eigen::Vector3d probe = first.rotation * vector_of(page.at("wind_probe")) + first.translation;
  std::vector<double> largest(frames, 0.0), squares(frames, 0.0);
  double vertices = 0;
  json placed = json::array();
  std::vector<std::string> notes;
  for (size_t t = 0; t < trees.size(); ++t) {
    json data = t == 0 ? page : tree_page_data(trees[t], &page);
    const TreePlacement place = make_tree_placement(trees[t].translation, trees[t].rotation_degrees);
    const json& plot = data.at("plot");
    double tree_vertices = 0;
    for (json& tree : data.at("trees")) {
      const Eigen::Vector3d at = place.rotation * vector_of(tree.at("position")) + place.translation;
      tree["position"] = {at.x(), at.y(), at.z()};
      tree["rotation"] = tree.at("rotation").get<double>() + trees[t].rotation_degrees;
      tree_vertices += vertex_count(tree);
      placed.push_back(std::move(tree));
    }
    for (size_t i = 0; i < frames; ++i) {
      largest[i] = std::max(largest[i], plot.at("max_displacement")[i].get<double>());
      const double rms = plot.at("rms_displacement")[i].get<double>();
      squares[i] += tree_vertices * rms * rms;
    }
    vertices += tree_vertices;
    notes.push_back(data.at("reduced").get<std::string>());
  }
  json rms = json::array();
  for (double s : squares) rms.push_back(vertices > 0 ? std::sqrt(s / vertices) : 0.0);
  page["title"] = name + " (" + page.at("generator").get<std::string>() + ")";
  page["plot"]["wind"] = std::move(wind);
  page["plot"]["max_displacement"] = largest;
  page["plot"]["rms_displacement"] = std::move(rms);
  page["wind_probe"] = {probe.x(), probe.y(), probe.z()};
  page["trees"] = std::move(placed);
  page["reduced"] = tree_reductions(trees, notes);
  std::string text = preview_page_text(name, page);
  if (text.size() <= max_page_bytes) return text;

  // Too large: the smallest stride whose frames and note fit.
  json& placed_trees = page["trees"];
  const std::string reductions = page["reduced"].get<std::string>();
  const auto note = [&](size_t stride) {
    char text[160];
    std::snprintf(text, sizeof text, "Reduced to fit %.0f MiB: 1 frame in %zu of the trees' pages kept, the others "
                  "interpolated.", double(max_page_bytes) / 1048576.0, stride);
    return reductions.empty() ? std::string(text) : std::string(text) + " " + reductions;
  };
  const double others = double(text.size()) - thinned_chars(placed_trees, 1) - double(json(reductions).dump().size());
  const auto bytes = [&](size_t stride) {
    return others + thinned_chars(placed_trees, stride) + double(json(note(stride)).dump().size());
  };
  size_t most = 0;
  for (const json& tree : placed_trees) most = std::max(most, tree.at("frames").at("sample").size());
  size_t stride = 2;
  while (stride < most && bytes(stride) > double(max_page_bytes)) ++stride;
  if (bytes(stride) > double(max_page_bytes))
    throw OutputError(name + ".html: the " + std::to_string(trees.size()) + " trees' meshes and two frames each take " +
                      std::to_string(static_cast<long long>(std::ceil(bytes(stride) / 1048576.0))) +
                      " MiB, above the page's limit of " + std::to_string(max_page_bytes >> 20) + " MiB (max_mib)");
  for (json& tree : placed_trees) thin(tree, stride);
  page["reduced"] = note(stride);
  text = preview_page_text(name, page);
  if (text.size() > max_page_bytes)
    throw OutputError(name + ".html: the page came to " + std::to_string(text.size()) + " bytes, above its limit of " +
                      std::to_string(max_page_bytes));
  return text;
}

void write_forest_page(const fs::path& path, const std::vector<ForestPageTree>& trees, size_t max_page_bytes) {
  write_text_output(path, forest_page(trees, path.stem().string(), max_page_bytes));
}

}  // namespace treeanim
