// The preview page (docs/outputs.md "Preview page"): one self-contained HTML file holding the
// bake as JSON with base64 arrays and the three.js viewer bundled at build time
// (src/formats/preview/viewer.js, embedded as kPreviewViewerJs), so it opens from disk with no
// network. A bake too large for kMaxPageBytes keeps fewer frames and quantized positions.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>

#include "common/errors.h"
#include "formats/base64.h"
#include "formats/frame_sink.h"
#include "files/output_file.h"
#include "formats/preview_page.h"
#include "tree/surface_materials.h"
#include "preview_viewer_js.h"
#include "sim/wind.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

// Bytes the page reserves besides what it counts (HTML shell, JSON keys, the reduction note).
constexpr size_t kPageSlack = 64 * 1024;

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

// How the frames travel: all of them as float32, all as int16 displacements from rest, or
// every stride-th as int16, whichever first fits the bytes left for them.
struct FramePlan {
  bool quantized = false;
  long long stride = 1;
};

// base64 bytes of `frames` frames of `vertices` vertices, float32 or int16.
double frame_page_bytes(size_t vertices, long long frames, bool quantized) {
  return 4.0 / 3.0 * double(frames) * double(vertices) * 3.0 * (quantized ? 2.0 : 4.0);
}

// vertices, frames written, bytes left for them => the plan (kept frames: 0, stride, 2 stride, ..., and the last).
FramePlan plan_frames(size_t vertices, long long frames, double budget) {
  if (frame_page_bytes(vertices, frames, false) <= budget) return {false, 1};
  const double one = frame_page_bytes(vertices, 1, true);
  const long long fit = std::max(2LL, static_cast<long long>(budget / one));
  return {true, std::max(1LL, (frames + fit - 2) / (fit - 1))};
}

class HtmlSink final : public FrameSink {
 public:
  HtmlSink(const OutputOptions& options, const fs::path& path, const TreeModel& model, const BakeInfo& info)
      : path_(path.extension() == ".html" ? path : fs::path(path.string() + ".html")), model_(model),
        info_(info), selection_{info.frame_start, info.frame_count, options.frame_step}, wind_(info.wind) {
    probe_ = 0.5 * (model.rest_positions.rowwise().minCoeff() + model.rest_positions.rowwise().maxCoeff());
    const double mesh = 4.0 / 3.0 * 12.0 * double(model.vertex_count() + model.triangle_count());
    const double plots = 140.0 * double(selection_.written());  // 7 numbers of ~20 characters a frame
    const double fixed = double(sizeof kPreviewViewerJs) + mesh + plots + double(kPageSlack);
    const double budget = double(options.max_page_bytes) - fixed;
    const double two_frames = frame_page_bytes(model.vertex_count(), std::min(2LL, selection_.written()), true);
    if (budget < two_frames)
      throw InputError(options.pointer + "/max_mib: the page needs " +
                       std::to_string(static_cast<long long>(std::ceil((fixed + two_frames) / 1048576.0))) +
                       " MiB at least for this tree (viewer, mesh and two frames)");
    plan_ = plan_frames(model.vertex_count(), selection_.written(), budget);
    max_page_bytes_ = options.max_page_bytes;
  }

  void for_each_target(const std::function<void(const fs::path&)>& visit) const override { visit(path_); }
  std::vector<fs::path> summary_paths() const override { return {path_}; }

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
    if (written_++ % plan_.stride != 0 && written_ != selection_.written()) return;
    kept_.push_back(written_ - 1);
    if (!plan_.quantized) {
      frames_.insert(frames_.end(), frame.positions.begin(), frame.positions.end());
      return;
    }
    for (size_t i = 0; i < n; ++i)
      frames_.push_back(frame.positions[i] - float(model_.rest_positions(Eigen::Index(i % 3), Eigen::Index(i / 3))));
  }

  void finish() override {
    nlohmann::json page;
    page["format"] = "treeanim-preview";
    page["version"] = 1;
    page["generator"] = info_.generator;
    page["title"] = path_.stem().string() + " (" + info_.generator + ")";
    page["fps"] = info_.fps;
    page["plot"] = plot_;
    page["colors"] = {{"bark", info_.materials[kMaterialBark].base_color_srgb},
                      {"leaf", info_.materials[kMaterialLeaf].base_color_srgb}};
    page["wind_probe"] = {probe_.x(), probe_.y(), probe_.z()};
    page["trees"] = nlohmann::json::array({tree_json()});
    page["reduced"] = reduction_note();
    const std::string text = preview_page_text(path_.stem().string(), page);
    if (text.size() > max_page_bytes_)
      throw OutputError(path_.string() + ": the page came to " + std::to_string(text.size()) +
                        " bytes, above its limit of " + std::to_string(max_page_bytes_));
    OutputFile file(temporary_, path_);
    file.write(text);
    file.close();
  }

 private:
  // The tree's mesh (bark triangles first) and its kept frames.
  nlohmann::json tree_json() {
    std::vector<uint32_t> sorted;
    sorted.reserve(model_.triangles.size());
    for (const std::vector<uint32_t>& faces : material_triangles(model_))
      for (uint32_t t : faces) sorted.insert(sorted.end(), &model_.triangles[3 * t], &model_.triangles[3 * t + 3]);
    const Eigen::Matrix3Xf rest = model_.rest_positions.cast<float>();
    nlohmann::json tree;
    tree["position"] = {0.0, 0.0, 0.0};
    tree["rotation"] = 0.0;
    tree["rest"] = base64_array(little_endian_bytes(rest.data(), size_t(rest.size())));
    tree["triangles"] = base64_array(little_endian_bytes(sorted.data(), sorted.size()));
    tree["bark_triangles"] =
        std::count(model_.triangle_material.begin(), model_.triangle_material.end(), uint8_t(kMaterialBark));
    tree["frames"]["sample"] = kept_;
    if (!plan_.quantized) {
      tree["frames"]["encoding"] = "float32";
      tree["frames"]["data"] = base64_array(little_endian_bytes(frames_.data(), frames_.size()));
      return tree;
    }
    // A step per vertex: a leaf that flew off does not coarsen the tree that stayed.
    const size_t V = model_.vertex_count();
    std::vector<float> steps(V, 0.0f);
    for (size_t i = 0; i < frames_.size(); ++i) steps[i / 3 % V] = std::max(steps[i / 3 % V], std::abs(frames_[i]));
    for (float& step : steps) step = step > 0 ? step / 32767.0f : 1e-6f;
    std::vector<int16_t> q(frames_.size());
    for (size_t i = 0; i < q.size(); ++i) q[i] = static_cast<int16_t>(std::lround(frames_[i] / steps[i / 3 % V]));
    std::vector<float> ordered = steps;
    std::nth_element(ordered.begin(), ordered.begin() + std::ptrdiff_t(V / 2), ordered.end());
    median_step_ = ordered[V / 2];
    largest_step_ = *std::max_element(steps.begin(), steps.end());
    tree["frames"]["encoding"] = "int16";
    tree["frames"]["step"] = base64_array(little_endian_bytes(steps.data(), steps.size()));
    tree["frames"]["data"] = base64_array(little_endian_bytes(q.data(), q.size()));
    return tree;
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
      std::snprintf(text + used, sizeof text - size_t(used), "; 1 frame in %lld kept (%zu of %lld), the others interpolated",
                    plan_.stride, kept_.size(), written_);
    return std::string(text) + ".";
  }

  fs::path path_;  // "<name>.html"
  fs::path temporary_;
  const TreeModel& model_;
  BakeInfo info_;
  FrameSelection selection_;
  WindField wind_;
  Eigen::Vector3d probe_;         // m, where the plotted wind is taken: the rest mesh's box centre, tree frame
  FramePlan plan_;
  size_t max_page_bytes_ = 0;
  nlohmann::json plot_ = nlohmann::json::object();  // per written frame: frame, time, wind, displacements
  long long written_ = 0;         // frames written so far
  std::vector<long long> kept_;   // (kept) indices of the written frames the page holds
  std::vector<float> frames_;     // (kept*V*3) m, positions (float32) or displacements (int16)
  double median_step_ = 0;        // m, the int16 encoding's step at the median vertex
  double largest_step_ = 0;       // m, and its largest
};

}  // namespace

std::unique_ptr<FrameSink> make_html_sink(const OutputOptions& options, const fs::path& path, const TreeModel& model,
                                          const BakeInfo& info) {
  return std::make_unique<HtmlSink>(options, path, model, info);
}

}  // namespace treeanim
