// The preview page (docs/outputs.md "Preview page"): one self-contained HTML file holding the
// bake as JSON with base64 arrays and the three.js viewer bundled at build time
// (src/formats/preview/viewer.js, embedded as kPreviewViewerJs), so it opens from disk with no
// network. The page is planned before the first frame from the sizes its parts will have
// (formats/preview_page.h), so a bake too large for its limit keeps fewer frames and quantized
// positions, and one that cannot fit at all is refused before simulating.
#include <algorithm>
#include <array>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>

#include "common/errors.h"
#include "formats/base64.h"
#include "formats/frame_sink.h"
#include "files/output_file.h"
#include "formats/preview_page.h"
#include "formats/sink_factories.h"
#include "tree/surface_materials.h"
#include "sim/wind.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

using nlohmann::json;

// A double at its longest, for the numbers a page's size is planned with before they are known.
constexpr double kLongest = -1.7976931348623157e308;

// values => their bytes in little-endian order (the page's typed arrays read them so).
template <typename T>
std::string little_endian_bytes(const T* values, size_t count) {
  std::string bytes(count * sizeof(T), '\0');
  std::memcpy(bytes.data(), values, bytes.size());
  if constexpr (std::endian::native == std::endian::big)
    for (size_t i = 0; i < bytes.size(); i += sizeof(T)) std::reverse(bytes.begin() + i, bytes.begin() + i + sizeof(T));
  return bytes;
}

std::string base64_array(const std::string& bytes) { return base64(bytes.data(), bytes.size()); }

// What a tree's page says besides its mesh, frames, plots and note.
struct PageHeader {
  std::string generator;
  double fps = 0;
  std::array<float, 3> bark{}, leaf{};  // sRGB
  long long bark_triangles = 0;         // the mesh's first triangles, bark; the leaves follow
};

// The tree of a page: its place (the forest page moves it), mesh (base64) and frames.
json tree_json(const PageHeader& header, std::string rest, std::string triangles, json frames, double place) {
  json tree;
  tree["position"] = {place, place, place};
  tree["rotation"] = place;
  tree["rest"] = std::move(rest);
  tree["triangles"] = std::move(triangles);
  tree["bark_triangles"] = header.bark_triangles;
  tree["colors"] = {{"bark", header.bark}, {"leaf", header.leaf}};  // a forest page keeps each tree's
  tree["frames"] = std::move(frames);
  return tree;
}

// The page's bake, named `name` (its file's stem).
json page_json(const PageHeader& header, const std::string& name, json plot, const json& probe, json tree,
               const std::string& note) {
  json page;
  page["format"] = "treeanim-preview";
  page["version"] = 1;
  page["generator"] = header.generator;
  page["title"] = name + " (" + header.generator + ")";
  page["fps"] = header.fps;
  page["plot"] = std::move(plot);
  page["colors"] = {{"bark", header.bark}, {"leaf", header.leaf}};
  page["wind_probe"] = probe;
  page["trees"] = json::array({std::move(tree)});
  page["reduced"] = note;
  return page;
}

// The page's text with every array, base64 text and the note empty, and the numbers that can
// differ in a forest page of this tree alone (place, wind probe) at their longest.
size_t skeleton_bytes(const PageHeader& header, const std::string& name, bool quantized) {
  json plot;
  for (const char* key : {"frame", "time", "wind", "max_displacement", "rms_displacement"}) plot[key] = json::array();
  json frames = {{"sample", json::array()}, {"encoding", quantized ? "int16" : "float32"}, {"data", ""}};
  if (quantized) frames["step"] = "";
  const json tree = tree_json(header, "", "", std::move(frames), kLongest);
  return preview_page_size(name, page_json(header, name, plot, {kLongest, kLongest, kLongest}, tree, ""));
}

// The page of a mesh and its written frames, numbered first ... last => what sizes it. `names`:
// the page's own and "forest", the forest page's (forest.html), which may hold this tree alone.
PreviewPageShape page_shape(const PageHeader& header, const std::vector<std::string>& names, size_t vertices,
                            size_t triangles, long long frames, long long first, long long last) {
  PreviewPageShape shape;
  shape.vertices = vertices;
  shape.triangles = triangles;
  shape.frames = size_t(std::max(0LL, frames));
  shape.frame_number_chars = std::max(std::to_string(first).size(), std::to_string(last).size());
  for (const std::string& name : names)
    for (bool quantized : {false, true})
      shape.skeleton[quantized] = std::max(shape.skeleton[quantized], skeleton_bytes(header, name, quantized));
  return shape;
}

// The page's header for `model` in `info`'s bake.
PageHeader page_header(const TreeModel& model, const BakeInfo& info) {
  return {info.generator, info.fps, info.materials[kMaterialBark].base_color_srgb,
          info.materials[kMaterialLeaf].base_color_srgb,
          std::count(model.triangle_material.begin(), model.triangle_material.end(), uint8_t(kMaterialBark))};
}

// "<name>.html" for an html output's path (".html" appended when missing).
fs::path page_path(const fs::path& path) { return path.extension() == ".html" ? path : fs::path(path.string() + ".html"); }

// The planned page's bytes as a MiB count for messages, rounded up.
long long mebibytes(double bytes) { return static_cast<long long>(std::ceil(bytes / 1048576.0)); }

class HtmlSink final : public FrameSink {
 public:
  HtmlSink(const OutputOptions& options, const fs::path& path, const TreeModel& model, const BakeInfo& info)
      : path_(page_path(path)), model_(model), info_(info),
        selection_{info.frame_start, info.frame_count, options.frame_step}, wind_(info.wind),
        max_page_bytes_(options.max_page_bytes), header_(page_header(model, info)) {
    probe_ = 0.5 * (model.rest_positions.rowwise().minCoeff() + model.rest_positions.rowwise().maxCoeff());
    plan_ = plan_preview_page(html_page_shape(options, model, info), max_page_bytes_);
    if (!plan_.fits)
      throw InputError(options.where() + "/max_mib: the page needs " + std::to_string(mebibytes(plan_.bytes)) +
                       " MiB at least for this tree (viewer, mesh, two frames and the plots of its " +
                       std::to_string(selection_.written()) + " written frames), more than max_mib = " +
                       std::to_string(max_page_bytes_ >> 20) +
                       ": raise max_mib where its range allows, raise frame_step or shorten the bake (the plots keep "
                       "every written frame), or leave the html output out");
  }

  std::vector<SummaryFile> summary_paths() const override { return {{path_}}; }

  void begin() override { temporary_ = staged_.stage(path_); }

  void write(const FrameData& frame) override {
    const size_t n = frame.positions.size();
    double largest = 0, squares = 0;
    for (size_t i = 0; i < n; i += 3) {
      double d2 = 0;
      for (int k = 0; k < 3; ++k) {
        const double d = double(frame.positions[i + k]) - model_.rest_positions(k, Eigen::Index(i / 3));
        d2 += d * d;
      }
      largest = std::max(largest, d2);
      squares += d2;
    }
    const TreePlacement& place = info_.placement;
    const Eigen::Vector3d air =
        place.rotation.transpose() * wind_.velocity(place.rotation * probe_ + place.translation, frame.time);
    plot_["frame"].push_back(frame.frame);
    plot_["time"].push_back(frame.time);
    for (int k = 0; k < 3; ++k) plot_["wind"].push_back(air[k]);
    plot_["max_displacement"].push_back(std::sqrt(largest));
    plot_["rms_displacement"].push_back(n ? std::sqrt(squares / double(n / 3)) : 0.0);
    if (written_++ % static_cast<long long>(plan_.stride) != 0 && written_ != selection_.written()) return;
    kept_.push_back(written_ - 1);
    frames_.insert(frames_.end(), frame.positions.begin(), frame.positions.end());
  }

  void finish() override {
    std::string text = page_text();
    // The plan bounds the text from above, so this loop does not run; should a page pass its
    // limit all the same, it keeps fewer frames rather than fail a bake that has simulated.
    while (text.size() > max_page_bytes_) {
      if (!thin_further(text.size() - max_page_bytes_))
        throw OutputError(path_.string() + ": the page came to " + std::to_string(text.size()) +
                          " bytes with two frames, above its limit of " + std::to_string(max_page_bytes_));
      text = page_text();
    }
    OutputFile file(temporary_, path_);
    file.write(text);
    file.close();
  }

 private:
  std::string page_text() {
    json tree = tree_with_frames();  // before the note, which gives the steps it chose
    const json probe = {probe_.x(), probe_.y(), probe_.z()};
    const std::string name = path_.stem().string();
    return preview_page_text(name, page_json(header_, name, plot_, probe, std::move(tree), reduction_note()));
  }

  // Quantizes float32 frames, else keeps 1 in k of the kept frames (and the last), k the least
  // that removes `excess` characters; false when even the first and the last are too many.
  bool thin_further(size_t excess) {
    if (!plan_.quantized) {
      plan_.quantized = true;
      return true;
    }
    const size_t values = 3 * model_.vertex_count();
    const size_t k = further_stride(kept_.size(), base64_chars(2 * values), excess);
    if (k == 0) return false;
    std::vector<long long> kept;
    std::vector<float> frames;
    for (size_t j : kept_frames(kept_.size(), k)) {
      kept.push_back(kept_[j]);
      frames.insert(frames.end(), frames_.begin() + std::ptrdiff_t(j * values),
                    frames_.begin() + std::ptrdiff_t((j + 1) * values));
    }
    kept_ = std::move(kept);
    frames_ = std::move(frames);
    plan_.stride *= k;
    return true;
  }

  // The tree's mesh (bark triangles first) and its kept frames.
  json tree_with_frames() {
    std::vector<uint32_t> sorted;
    sorted.reserve(model_.triangles.size());
    for (const std::vector<uint32_t>& faces : material_triangles(model_))
      for (uint32_t t : faces) sorted.insert(sorted.end(), &model_.triangles[3 * t], &model_.triangles[3 * t + 3]);
    const Eigen::Matrix3Xf rest = model_.rest_positions.cast<float>();
    std::string rest_text = base64_array(little_endian_bytes(rest.data(), size_t(rest.size())));
    std::string triangles = base64_array(little_endian_bytes(sorted.data(), sorted.size()));
    json frames = {{"sample", kept_}};
    if (!plan_.quantized) {
      frames["encoding"] = "float32";
      frames["data"] = base64_array(little_endian_bytes(frames_.data(), frames_.size()));
      return tree_json(header_, std::move(rest_text), std::move(triangles), std::move(frames), 0.0);
    }
    // Displacements from the float32 rest pose, a step per vertex: a leaf that flew off does not
    // coarsen the tree that stayed.
    const size_t V = model_.vertex_count();
    std::vector<float> displacement(frames_.size());
    for (size_t i = 0; i < frames_.size(); ++i) displacement[i] = frames_[i] - rest(Eigen::Index(i % 3), Eigen::Index(i / 3 % V));
    std::vector<float> steps(V, 0.0f);
    for (size_t i = 0; i < displacement.size(); ++i)
      steps[i / 3 % V] = std::max(steps[i / 3 % V], std::abs(displacement[i]));
    for (float& step : steps) step = step > 0 ? step / 32767.0f : 1e-6f;
    std::vector<int16_t> q(displacement.size());
    for (size_t i = 0; i < q.size(); ++i) q[i] = static_cast<int16_t>(std::lround(displacement[i] / steps[i / 3 % V]));
    std::vector<float> ordered = steps;
    std::nth_element(ordered.begin(), ordered.begin() + std::ptrdiff_t(V / 2), ordered.end());
    median_step_ = ordered[V / 2];
    largest_step_ = *std::max_element(steps.begin(), steps.end());
    frames["encoding"] = "int16";
    frames["step"] = base64_array(little_endian_bytes(steps.data(), steps.size()));
    frames["data"] = base64_array(little_endian_bytes(q.data(), q.size()));
    return tree_json(header_, std::move(rest_text), std::move(triangles), std::move(frames), 0.0);
  }

  // "" for a page holding the whole bake, else what was reduced to fit.
  std::string reduction_note() const {
    if (!plan_.quantized) return "";
    char text[320];
    const int used = std::snprintf(text, sizeof text,
                                   "Reduced to fit %.0f MiB: positions quantized (steps %.3g mm at the median vertex, "
                                   "%.3g mm at most)", double(max_page_bytes_) / 1048576.0, median_step_ * 1000.0,
                                   largest_step_ * 1000.0);
    if (plan_.stride > 1)
      std::snprintf(text + used, sizeof text - size_t(used), "; 1 frame in %zu kept (%zu of %lld), the others interpolated",
                    plan_.stride, kept_.size(), written_);
    return std::string(text) + ".";
  }

  fs::path path_;  // "<name>.html"
  fs::path temporary_;
  const TreeModel& model_;
  BakeInfo info_;
  FrameSelection selection_;
  WindField wind_;
  size_t max_page_bytes_;
  PageHeader header_;
  Eigen::Vector3d probe_;         // m, where the plotted wind is taken: the rest mesh's box centre, tree frame
  PreviewPagePlan plan_;
  json plot_ = json::object();    // per written frame: frame, time, wind, displacements
  long long written_ = 0;         // frames written so far
  std::vector<long long> kept_;   // (kept) indices of the written frames the page holds
  std::vector<float> frames_;     // (kept*V*3) m, their positions
  double median_step_ = 0;        // m, the int16 encoding's step at the median vertex
  double largest_step_ = 0;       // m, and its largest
};

}  // namespace

void html_targets(const OutputOptions&, const fs::path& path, const FrameSelection&, const TargetVisitor& visit) {
  visit(page_path(path), TargetKind::kFile);
}

std::unique_ptr<FrameSink> make_html_sink(const OutputOptions& options, const fs::path& path, const TreeModel& model,
                                          const BakeInfo& info) {
  return std::make_unique<HtmlSink>(options, path, model, info);
}

PreviewPageShape html_page_shape(const OutputOptions& options, const TreeModel& model, const BakeInfo& info) {
  const FrameSelection selection{info.frame_start, info.frame_count, options.frame_step};
  const long long written = selection.written();
  return page_shape(page_header(model, info), {page_path(options.path).stem().string(), "forest"},
                    model.vertex_count(), model.triangle_count(), written, selection.start,
                    selection.start + std::max(0LL, written - 1) * selection.step);
}

double html_output_bytes(const OutputOptions& options, size_t vertices, size_t triangles, size_t, long long frames) {
  // Before the bake its generator, colours and ids are not known: each at its longest.
  const PageHeader header{std::string(64, 'g'), kLongest, {-FLT_MAX, -FLT_MAX, -FLT_MAX},
                          {-FLT_MAX, -FLT_MAX, -FLT_MAX}, static_cast<long long>(triangles)};
  const std::string stem = page_path(options.path).stem().string();
  const long long written = (frames + options.frame_step - 1) / options.frame_step;
  const PreviewPageShape shape = page_shape(header, {stem, std::string(64, 'i'), "forest"}, vertices, triangles,
                                            written, std::numeric_limits<long long>::min(), 0);
  // Every frame as float32, or else a page reduced to its limit.
  return std::min(preview_page_bytes(shape, false, 1), double(options.max_page_bytes));
}

}  // namespace treeanim
