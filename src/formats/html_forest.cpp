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

// A tree's page => its bake, checked to plot the frames at `times` (the first tree's) when given.
json tree_page_data(const ForestPageTree& tree, const json* times) {
  std::string text, reason;
  if (!read_text_file(tree.page, text, reason, kMaxTextFileBytes, TextFileRole::kOwnOutput))
    throw OutputError(tree.page.string() + ": tree " + tree.id + "'s preview page cannot be read (" + reason + ")");
  json data = preview_page_data(text, tree.page.string());
  if (times && data.at("plot").at("time") != *times)
    throw OutputError(tree.page.string() + ": tree " + tree.id + "'s page plots other frames than " +
                      "the first tree's");
  return data;
}

// A tree page's trees (one, as the html sink writes them), placed where the forest puts the tree.
json placed_trees(json& data, const ForestPageTree& tree) {
  const TreePlacement place = make_tree_placement(tree.translation, tree.rotation_degrees);
  json placed = std::move(data.at("trees"));
  for (json& one : placed) {
    const Eigen::Vector3d at = place.rotation * vector_of(one.at("position")) + place.translation;
    one["position"] = {at.x(), at.y(), at.z()};
    one["rotation"] = one.at("rotation").get<double>() + tree.rotation_degrees;
  }
  return placed;
}

// Vertices of a tree of the page: its rest positions are float32 x y z, 16 base64 characters.
double vertex_count(const json& tree) { return double(tree.at("rest").get_ref<const std::string&>().size()) / 16.0; }

// Base64 characters of one kept frame: a frame is 12 or 6 bytes a vertex, a multiple of 3, so
// each frame is a run of whole characters and frames can be dropped from the text as it is.
size_t frame_chars(const json& tree) {
  return tree.at("frames").at("data").get_ref<const std::string&>().size() /
         std::max<size_t>(1, tree.at("frames").at("sample").size());
}

void thin(json& tree, size_t stride) {
  json& frames = tree.at("frames");
  const std::string& data = frames.at("data").get_ref<const std::string&>();
  const size_t chars = frame_chars(tree);
  json sample = json::array();
  std::string kept;
  for (size_t j : kept_frames(frames.at("sample").size(), stride)) {
    sample.push_back(frames.at("sample")[j]);
    kept.append(data, j * chars, chars);
  }
  frames["sample"] = std::move(sample);
  frames["data"] = std::move(kept);
}

// What a tree page's trees take in the forest page.
struct PageSize {
  size_t chars = 0;                                // their JSON, placed, with the commas between them
  std::vector<std::pair<size_t, size_t>> frames;   // each tree's kept frames and base64 characters of one
};

// What the trees' own pages reduced, in a sentence (the first one's note quoted unless `quote`
// is false); "" when none did.
std::string tree_reductions(const std::vector<ForestPageTree>& trees, const std::vector<std::string>& notes,
                            bool quote) {
  const auto first = std::find_if(notes.begin(), notes.end(), [](const std::string& n) { return !n.empty(); });
  if (first == notes.end()) return "";
  const long long count = std::count_if(notes.begin(), notes.end(), [](const std::string& n) { return !n.empty(); });
  const std::string reduced = std::to_string(count) + " of " + std::to_string(notes.size()) + " tree pages were reduced";
  return quote ? reduced + "; tree " + trees[size_t(first - notes.begin())].id + "'s says: " + *first : reduced + ".";
}

// The forest page's note: the trees it leaves out, the frames it thins and what the shown trees'
// pages reduced, within kPreviewNoteRoom.
std::string forest_note(const std::vector<ForestPageTree>& trees, std::vector<std::string> notes, size_t shown,
                        size_t stride, size_t max_page_bytes) {
  notes.resize(shown);
  std::vector<std::string> parts;
  char text[160];
  if (shown < trees.size()) {
    std::snprintf(text, sizeof text, "the first %zu of %zu trees shown, the others left out", shown, trees.size());
    parts.push_back(text);
  }
  if (stride > 1) {
    std::snprintf(text, sizeof text, "1 frame in %zu of the trees' pages kept, the others interpolated", stride);
    parts.push_back(text);
  }
  std::string note;
  if (!parts.empty()) {
    std::snprintf(text, sizeof text, "Reduced to fit %.0f MiB: ", double(max_page_bytes) / 1048576.0);
    note = text + parts[0] + (parts.size() > 1 ? "; " + parts[1] : "") + ".";
  }
  for (bool quote : {true, false}) {
    const std::string reductions = tree_reductions(trees, notes, quote);
    const std::string whole = note.empty() || reductions.empty() ? note + reductions : note + " " + reductions;
    if (script_json(whole).size() <= kPreviewNoteRoom) return whole;
  }
  return note;
}

}  // namespace

std::string forest_page(const std::vector<ForestPageTree>& trees, const std::string& name, size_t max_page_bytes) {
  // Pass 1, a page at a time: the plots over every tree and what each tree takes.
  json page = tree_page_data(trees.at(0), nullptr);
  const json times = page.at("plot").at("time");
  const size_t frames = times.size();
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
  std::vector<PageSize> sizes;
  std::vector<std::string> notes;
  for (size_t t = 0; t < trees.size(); ++t) {
    json other;
    json& data = t == 0 ? page : (other = tree_page_data(trees[t], &times));
    const json& plot = data.at("plot");
    PageSize size;
    double tree_vertices = 0;
    for (const json& tree : placed_trees(data, trees[t])) {
      tree_vertices += vertex_count(tree);
      size.chars += script_json(tree).size() + (size.frames.empty() ? 0 : 1);
      size.frames.emplace_back(tree.at("frames").at("sample").size(), frame_chars(tree));
    }
    for (size_t i = 0; i < frames; ++i) {
      largest[i] = std::max(largest[i], plot.at("max_displacement")[i].get<double>());
      const double rms = plot.at("rms_displacement")[i].get<double>();
      squares[i] += tree_vertices * rms * rms;
    }
    vertices += tree_vertices;
    sizes.push_back(std::move(size));
    notes.push_back(data.at("reduced").get<std::string>());
  }
  json rms = json::array();
  for (double s : squares) rms.push_back(vertices > 0 ? std::sqrt(s / vertices) : 0.0);
  page["title"] = name + " (" + page.at("generator").get<std::string>() + ")";
  page["plot"]["wind"] = std::move(wind);
  page["plot"]["max_displacement"] = largest;
  page["plot"]["rms_displacement"] = std::move(rms);
  page["wind_probe"] = {probe.x(), probe.y(), probe.z()};
  page["trees"] = json::array();
  page["reduced"] = "";

  // The bytes of the page with the first `shown` trees, their frames thinned by `stride`: an
  // upper bound (a thinned tree's shorter list of frame indices is not counted).
  const size_t base = preview_page_text(name, page).size();
  const auto bytes = [&](size_t shown, size_t stride) {
    size_t chars = base + shown - 1 + script_json(forest_note(trees, notes, shown, stride, max_page_bytes)).size() - 2;
    for (size_t t = 0; t < shown; ++t) {
      chars += sizes[t].chars;
      for (const auto& [kept, one] : sizes[t].frames) chars -= (kept - kept_frame_count(kept, stride)) * one;
    }
    return chars;
  };
  // The stride that keeps two frames of every tree among the first `shown`.
  const auto widest = [&](size_t shown) {
    size_t most = 2;
    for (size_t t = 0; t < shown; ++t)
      for (const auto& frame : sizes[t].frames) most = std::max(most, frame.first);
    return most - 1;
  };
  // As many trees as fit with two frames each, then the smallest stride. A tree's page leaves
  // room for a forest page of it alone, so the first tree always fits.
  size_t shown = 0;
  while (shown < trees.size() && bytes(shown + 1, widest(shown + 1)) <= max_page_bytes) ++shown;
  if (shown == 0)
    throw OutputError(name + ".html: tree " + trees[0].id + "'s mesh and two frames alone take " +
                      std::to_string(static_cast<long long>(std::ceil(double(bytes(1, widest(1))) / 1048576.0))) +
                      " MiB, above the page's limit of " + std::to_string(max_page_bytes >> 20) +
                      " MiB (max_mib): its page was not written for this limit");
  size_t stride = 1;
  if (bytes(shown, 1) > max_page_bytes) {
    size_t too_small = 1;
    stride = widest(shown);
    while (stride - too_small > 1) {
      const size_t mid = too_small + (stride - too_small) / 2;
      (bytes(shown, mid) <= max_page_bytes ? stride : too_small) = mid;
    }
  }

  // Pass 2: the shown trees again, thinned.
  for (size_t t = 0; t < shown; ++t) {
    json data = tree_page_data(trees[t], &times);
    for (json& tree : placed_trees(data, trees[t])) {
      if (stride > 1) thin(tree, stride);
      page["trees"].push_back(std::move(tree));
    }
  }
  page["reduced"] = forest_note(trees, notes, shown, stride, max_page_bytes);
  std::string text = preview_page_text(name, page);
  if (text.size() > max_page_bytes)  // bytes() bounds the text from above
    throw OutputError(name + ".html: the page came to " + std::to_string(text.size()) + " bytes, above its limit of " +
                      std::to_string(max_page_bytes));
  return text;
}

void write_forest_page(const fs::path& path, const std::vector<ForestPageTree>& trees, size_t max_page_bytes) {
  write_text_output(path, forest_page(trees, path.stem().string(), max_page_bytes));
}

}  // namespace treeanim
