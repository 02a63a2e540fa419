// One animated GLB: the rest mesh, one morph target per written frame (displacements from the
// rest pose) and an animation on the node's `weights`, one-hot per frame with LINEAR
// interpolation, so a player blends neighbouring frames at in-between times. assimp 5.2 cannot
// export morph-weight animation (assimp GitHub issue #5352), so the container is written here with
// nlohmann_json, streamed: the JSON chunk's room is reserved up front (its numbers at their
// longest) and filled in by finish(), the frames go straight to the BIN chunk.
//
// The mesh is formats/gltf_mesh.h's: one vertex set, a primitive per material, each primitive with
// the same targets.
//
// BIN layout (every part a multiple of 4 bytes): indices u32 [T*3] grouped by material, rest
// positions f32 [N*3], (with normals: rest normals f32 [N*3]), UVs f32 [N*2], (with vertex colours:
// f32 [N*3]), targets f32 [F][N*3] (with normals [F][2][N*3]: a frame's position then normal
// displacements), times f32 [F], weights f32 [F*F].
#include <algorithm>
#include <array>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>

#include "common/errors.h"
#include "files/output_file.h"
#include "files/staged_files.h"
#include "formats/frame_sink.h"
#include "formats/glb_size.h"
#include "formats/gltf_mesh.h"
#include "formats/sink_factories.h"
#include "formats/rest_positions_f32.h"
#include "formats/vertex_normals.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

constexpr uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A;     // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;      // "BIN\0"
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;
constexpr int kFloat = 5126, kUnsignedInt = 5125;

// Per-axis bounds of a VEC3 accessor (glTF requires them on POSITION, morph targets included).
struct Bounds {
  std::array<float, 3> min{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                           std::numeric_limits<float>::max()};
  std::array<float, 3> max{-std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
                           -std::numeric_limits<float>::max()};
  void add(const float* xyz) {
    for (int a = 0; a < 3; ++a) {
      min[a] = std::min(min[a], xyz[a]);
      max[a] = std::max(max[a], xyz[a]);
    }
  }
};

// Everything the JSON chunk says, so it can be rendered with placeholders (to reserve room)
// and for real (in finish()).
// What an animated GLB carries besides positions.
struct GlbLayout {
  bool normals = false;  // NORMAL on the mesh and on every target
  bool loop = false;     // a closing key brings the first frame back at the loop's end
  bool colors = false;   // COLOR_0, the per-leaf colour factors
  std::array<uint64_t, kMaterialCount> corners{};  // index count of each material's primitive
  std::array<SurfaceMaterial, kMaterialCount> materials;
  uint64_t primitives() const { return uint64_t(std::count_if(corners.begin(), corners.end(), [](uint64_t c) { return c > 0; })); }
  // Animation keys for f frames: one per frame, and the closing one of a loop.
  uint64_t keys(uint64_t f) const { return f + (loop && f > 0 ? 1 : 0); }
};

struct GlbContent {
  size_t vertices = 0, triangles = 0, frames = 0;
  GlbLayout layout;
  std::string generator;
  std::optional<Bounds> rest;             // nullopt: render the longest placeholder numbers
  std::vector<Bounds> targets;            // (frames) displacement bounds
  std::vector<std::string> target_names;  // (frames) "frame_0001", ...
  float time_min = 0, time_max = 0;
  bool placeholder = false;
};

nlohmann::json bounds_json(const std::array<float, 3>& values, bool placeholder) {
  // The longest text a double can print as, so real values never need more room.
  constexpr double kLongest = -1.7976931348623157e308;
  if (placeholder) return {kLongest, kLongest, kLongest};
  return {double(values[0]), double(values[1]), double(values[2])};
}

// Bytes of one vertex attribute per vertex set that a frame's target holds: 1, or 2 with normals.
uint64_t target_sets(bool normals) { return normals ? 2 : 1; }

// Bytes of the static vertex attributes: rest positions (and normals), UVs, (colours).
uint64_t static_vertex_bytes(uint64_t n, const GlbLayout& layout) {
  return 12 * n * target_sets(layout.normals) + 8 * n + (layout.colors ? 12 * n : 0);
}

uint64_t bin_bytes(size_t vertices, size_t triangles, size_t frames, const GlbLayout& layout) {
  const uint64_t n = vertices, f = frames, sets = target_sets(layout.normals), keys = layout.keys(f);
  return 12 * uint64_t(triangles) + static_vertex_bytes(n, layout) + 12 * n * sets * f + 4 * keys + 4 * f * keys;
}

// model, bake, options => what the GLB carries.
GlbLayout glb_layout(const TreeModel& model, const BakeInfo& info, bool normals) {
  GlbLayout layout{normals, info.loop, !info.vertex_colors.empty(), {}, info.materials};
  for (uint8_t m : model.triangle_material) layout.corners[m] += 3;
  return layout;
}

std::string render_json(const GlbContent& c) {
  using nlohmann::json;
  const uint64_t n = c.vertices, f = c.frames, t = c.triangles, sets = target_sets(c.layout.normals);
  const uint64_t keys = c.layout.keys(f);
  const uint64_t indices_bytes = 12 * t, rest_bytes = 12 * n * sets, uv_bytes = 8 * n;
  const uint64_t frame_bytes = 12 * n * sets, targets_bytes = frame_bytes * f;
  const uint64_t targets_offset = indices_bytes + static_vertex_bytes(n, c.layout);
  const uint64_t times_offset = targets_offset + targets_bytes;

  // Views 0-2: indices, rest positions (and normals, one view: stride 12), UVs; 3: colours.
  json views = json::array({
      {{"buffer", 0}, {"byteOffset", 0}, {"byteLength", indices_bytes}, {"target", kElementArrayBuffer}},
      {{"buffer", 0}, {"byteOffset", indices_bytes}, {"byteLength", rest_bytes}, {"byteStride", 12},
       {"target", kArrayBuffer}},
      {{"buffer", 0}, {"byteOffset", indices_bytes + rest_bytes}, {"byteLength", uv_bytes},
       {"target", kArrayBuffer}},
  });
  json accessors = json::array({
      {{"bufferView", 1}, {"componentType", kFloat}, {"count", n}, {"type", "VEC3"},
       {"min", bounds_json(c.rest ? c.rest->min : std::array<float, 3>{}, c.placeholder)},
       {"max", bounds_json(c.rest ? c.rest->max : std::array<float, 3>{}, c.placeholder)}},
      {{"bufferView", 2}, {"componentType", kFloat}, {"count", n}, {"type", "VEC2"}},
  });
  json attributes = {{"POSITION", 0}, {"TEXCOORD_0", 1}};
  if (c.layout.normals) {
    attributes["NORMAL"] = accessors.size();
    accessors.push_back({{"bufferView", 1}, {"byteOffset", 12 * n}, {"componentType", kFloat}, {"count", n},
                         {"type", "VEC3"}});
  }
  if (c.layout.colors) {
    attributes["COLOR_0"] = accessors.size();
    views.push_back({{"buffer", 0}, {"byteOffset", indices_bytes + rest_bytes + uv_bytes}, {"byteLength", 12 * n},
                     {"target", kArrayBuffer}});
    accessors.push_back({{"bufferView", views.size() - 1}, {"componentType", kFloat}, {"count", n}, {"type", "VEC3"}});
  }
  // A primitive per material that has triangles, over its part of the index view.
  json primitives = json::array();
  uint64_t first_corner = 0;
  for (size_t m = 0; m < kMaterialCount; ++m) {
    const uint64_t count = c.layout.corners[m];
    if (count == 0) continue;
    primitives.push_back({{"attributes", attributes}, {"indices", accessors.size()}, {"material", m}, {"mode", 4}});
    accessors.push_back({{"bufferView", 0}, {"byteOffset", 4 * first_corner}, {"componentType", kUnsignedInt},
                         {"count", count}, {"type", "SCALAR"}});
    first_corner += count;
  }
  json mesh = {{"name", "tree"}};
  json document = {
      {"asset", {{"version", "2.0"}, {"generator", c.generator},
                 {"extras", {{"units", "m"}, {"up_axis", "Y"}}}}},
      {"scene", 0},
      {"scenes", json::array({{{"nodes", json::array({0})}}})},
      {"nodes", json::array({{{"mesh", 0}, {"name", "tree"}}})},
  };
  if (f > 0) {
    // Several target accessors share one view: glTF then requires its byteStride.
    const size_t targets_view = views.size();
    views.push_back({{"buffer", 0}, {"byteOffset", targets_offset}, {"byteLength", targets_bytes},
                     {"byteStride", 12}, {"target", kArrayBuffer}});
    views.push_back({{"buffer", 0}, {"byteOffset", times_offset}, {"byteLength", 4 * keys}});
    views.push_back({{"buffer", 0}, {"byteOffset", times_offset + 4 * keys}, {"byteLength", 4 * f * keys}});
    json targets = json::array();
    for (uint64_t k = 0; k < f; ++k) {
      const Bounds bounds = c.placeholder ? Bounds{} : c.targets[k];
      targets.push_back({{"POSITION", accessors.size()}});
      accessors.push_back({{"bufferView", targets_view}, {"byteOffset", frame_bytes * k}, {"componentType", kFloat},
                           {"count", n}, {"type", "VEC3"}, {"min", bounds_json(bounds.min, c.placeholder)},
                           {"max", bounds_json(bounds.max, c.placeholder)}});
      if (c.layout.normals) {  // glTF asks bounds of POSITION only
        targets.back()["NORMAL"] = accessors.size();
        accessors.push_back({{"bufferView", targets_view}, {"byteOffset", frame_bytes * k + 12 * n},
                             {"componentType", kFloat}, {"count", n}, {"type", "VEC3"}});
      }
    }
    const size_t times_accessor = accessors.size();
    const double longest = -1.7976931348623157e308;
    accessors.push_back({{"bufferView", targets_view + 1}, {"componentType", kFloat}, {"count", keys}, {"type", "SCALAR"},
                         {"min", json::array({c.placeholder ? longest : double(c.time_min)})},
                         {"max", json::array({c.placeholder ? longest : double(c.time_max)})}});
    accessors.push_back({{"bufferView", targets_view + 2}, {"componentType", kFloat}, {"count", f * keys},
                         {"type", "SCALAR"}});
    for (json& primitive : primitives) primitive["targets"] = targets;
    mesh["weights"] = json(std::vector<double>(f, 0.0));
    mesh["extras"] = {{"targetNames", c.target_names}};
    document["animations"] = json::array({{
        {"name", "wind"},
        {"samplers", json::array({{{"input", times_accessor}, {"output", times_accessor + 1},
                                   {"interpolation", "LINEAR"}}})},
        {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}}})},
    }});
  }
  mesh["primitives"] = primitives;
  document["meshes"] = json::array({mesh});
  document["materials"] = gltf_materials_json(c.layout.materials);
  document["buffers"] = json::array({{{"byteLength", bin_bytes(n, t, f, c.layout)}}});
  document["bufferViews"] = views;
  document["accessors"] = accessors;
  std::string text = document.dump();
  text.resize((text.size() + 3) / 4 * 4, ' ');  // chunks are 4-byte aligned; spaces pad JSON
  return text;
}

std::vector<std::string> target_names(const FrameSelection& selection) {
  std::vector<std::string> names;
  for (long long k = 0; k < selection.written(); ++k) {
    char name[40];
    std::snprintf(name, sizeof name, "frame_%04lld", selection.start + k * selection.step);
    names.push_back(name);
  }
  return names;
}

// The JSON with every number at its longest, for `frames` frames named as in `names`.
GlbContent placeholder_content(const TreeModel& model, const std::string& generator, const GlbLayout& layout,
                               size_t frames, std::vector<std::string> names) {
  GlbContent content;
  content.layout = layout;
  content.vertices = model.vertex_count();
  content.triangles = model.triangle_count();
  content.frames = frames;
  content.generator = generator;
  content.target_names = std::move(names);
  content.placeholder = true;
  return content;
}

// An upper bound of the GLB's bytes for any frame count, in O(1) time and memory (a scene may ask
// for 10 million frames): the JSON of one frame rendered at its longest, plus the longest text
// each further frame adds, plus room for the few totals whose digits grow with the frame count.
class GlbSizeBound {
 public:
  GlbSizeBound(const TreeModel& model, const std::string& generator, const GlbLayout& layout)
      : vertices_(model.vertex_count()), triangles_(model.triangle_count()), layout_(layout) {
    using nlohmann::json;
    constexpr uint64_t kMax = std::numeric_limits<uint64_t>::max();
    constexpr double kLongest = -1.7976931348623157e308;
    const json longest3 = {kLongest, kLongest, kLongest};
    const json accessor = {{"bufferView", 3}, {"byteOffset", kMax}, {"componentType", kFloat}, {"count", kMax},
                           {"type", "VEC3"}, {"min", longest3}, {"max", longest3}};
    json target = {{"POSITION", kMax}};
    if (layout.normals) target["NORMAL"] = kMax;
    const json name = "frame_-9223372036854775808";
    per_frame_json_ = target_sets(layout.normals) * (accessor.dump().size() + 1) +
                      layout.primitives() * (target.dump().size() + 1) + name.dump().size() +
                      json(0.0).dump().size() + 3;
    no_frame_json_ = render_json(placeholder_content(model, generator, layout, 0, {})).size();
    one_frame_json_ = render_json(placeholder_content(model, generator, layout, 1, {name.get<std::string>()})).size();
  }

  uint64_t bytes(uint64_t frames) const {
    // Totals that grow with the frame count: view and buffer lengths and offsets, counts.
    constexpr uint64_t kGrowingDigits = 16 * 20;
    const uint64_t json = frames == 0 ? no_frame_json_ : one_frame_json_ + (frames - 1) * per_frame_json_ + kGrowingDigits;
    return glb_bytes(json + 3, bin_bytes(vertices_, triangles_, frames, layout_));
  }

  // The largest frame count (written frames) whose GLB fits in `limit` bytes.
  uint64_t frames_within(uint64_t limit) const {
    // 4 F^2 bytes of weights alone pass 4 GiB from F = 2^15 on; 2^20 keeps bytes() far from overflow.
    uint64_t fits = 0, too_many = uint64_t(1) << 20;
    while (too_many - fits > 1) {
      const uint64_t mid = fits + (too_many - fits) / 2;
      (bytes(mid) <= limit ? fits : too_many) = mid;
    }
    return fits;
  }

  static uint64_t glb_bytes(uint64_t json_bytes, uint64_t bin) { return 12 + 8 + json_bytes + 8 + bin; }

 private:
  size_t vertices_, triangles_;
  GlbLayout layout_;
  uint64_t per_frame_json_ = 0, no_frame_json_ = 0, one_frame_json_ = 0;
};

class GlbSink final : public FrameSink {
 public:
  GlbSink(const OutputOptions& options, fs::path path, const TreeModel& model, const BakeInfo& info)
      : path_(std::move(path)), model_(model),
        selection_{info.frame_start, info.frame_count, options.frame_step},
        loop_end_time_(info.loop_end_time), vertex_colors_(info.vertex_colors),
        content_(placeholder_content(model, info.generator, glb_layout(model, info, options.normals),
                                     size_t(selection_.written()),
                                     target_names(selection_))) {}

  std::vector<SummaryFile> summary_paths() const override { return {{path_}}; }

  void begin() override {
    reserved_json_ = render_json(content_).size();
    rest_ = rest_positions_f32(model_);
    file_.emplace(staged_.stage(path_), path_);
    file_->write(std::string(12 + 8 + reserved_json_ + 8, '\0'));  // header and JSON, filled by finish()
    for (uint32_t index : material_indices(model_).corners) file_->write_u32_le(index);
    file_->write_f32_le(rest_.data(), rest_.size());
    if (content_.layout.normals) {
      rest_normals_ = rest_normals(model_);
      file_->write_f32_le(rest_normals_.data(), rest_normals_.size());
    }
    const std::vector<float> uvs = gltf_uvs(model_);
    file_->write_f32_le(uvs.data(), uvs.size());
    file_->write_f32_le(vertex_colors_.data(), vertex_colors_.size());
    Bounds rest;
    for (size_t i = 0; i < rest_.size(); i += 3) rest.add(&rest_[i]);
    content_.rest = rest;
  }

  void write(const FrameData& frame) override {
    displacement_.resize(rest_.size());
    Bounds bounds;
    for (size_t i = 0; i < rest_.size(); i += 3) {
      for (int a = 0; a < 3; ++a) displacement_[i + a] = frame.positions[i + a] - rest_[i + a];
      bounds.add(&displacement_[i]);
    }
    file_->write_f32_le(displacement_.data(), displacement_.size());
    if (content_.layout.normals) {
      for (size_t i = 0; i < rest_normals_.size(); ++i) displacement_[i] = frame.normals[i] - rest_normals_[i];
      file_->write_f32_le(displacement_.data(), displacement_.size());
    }
    content_.targets.push_back(bounds);
    times_.push_back(float(frame.time));
  }

  void finish() override {
    const size_t f = content_.frames;
    if (times_.size() != f)
      throw OutputError(path_.string() + ": the animated GLB was laid out for " + std::to_string(f) +
                        " frames but the bake delivered " + std::to_string(times_.size()));
    const size_t keys = content_.layout.keys(f);
    if (keys > f) times_.push_back(float(loop_end_time_));  // the loop's closing key
    file_->write_f32_le(times_.data(), keys);
    std::vector<float> weights(f);
    for (size_t k = 0; k < keys; ++k) {  // key k: target k fully on, all others off; the closing key: target 0
      std::fill(weights.begin(), weights.end(), 0.0f);
      weights[k % f] = 1.0f;
      file_->write_f32_le(weights.data(), f);
    }
    if (f > 0) {
      content_.time_min = times_.front();
      content_.time_max = times_.back();
    }
    content_.placeholder = false;
    std::string json = render_json(content_);
    // Every number was reserved at its longest, so the JSON fits its room; were it longer, padding
    // it to the room would cut it and leave a broken file under the final name.
    if (json.size() > reserved_json_)
      throw OutputError(path_.string() + ": the animated GLB's JSON came to " + std::to_string(json.size()) +
                        " bytes, above the " + std::to_string(reserved_json_) + " reserved for it");
    json.resize(reserved_json_, ' ');
    file_->seek(0);
    file_->write_u32_le(kGlbMagic);
    file_->write_u32_le(2);
    const uint64_t bin = bin_bytes(content_.vertices, content_.triangles, f, content_.layout);
    file_->write_u32_le(uint32_t(GlbSizeBound::glb_bytes(reserved_json_, bin)));
    file_->write_u32_le(uint32_t(reserved_json_));
    file_->write_u32_le(kChunkJson);
    file_->write(json);
    file_->write_u32_le(uint32_t(bin));
    file_->write_u32_le(kChunkBin);
    file_->close();
    file_.reset();
  }

  void abort() noexcept override {
    file_.reset();
    staged_.discard();
  }

 private:
  fs::path path_;
  const TreeModel& model_;
  FrameSelection selection_;
  double loop_end_time_;  // s, the closing key's time when the bake is a loop
  std::vector<float> vertex_colors_;   // (N*3) COLOR_0, or empty
  GlbContent content_;
  size_t reserved_json_ = 0;           // bytes of the JSON chunk
  std::vector<float> rest_;            // (N*3) m, float rest pose the displacements are taken from
  std::vector<float> rest_normals_;    // (N*3) unit, with normals: what the normal targets displace
  std::vector<float> displacement_;    // (N*3) m, scratch for one target
  std::vector<float> times_;           // (frames written) s
  std::optional<OutputFile> file_;
};

}  // namespace

uint64_t animated_glb_bytes(const TreeModel& model, const BakeInfo& info, int frame_step, bool normals) {
  const FrameSelection selection{info.frame_start, info.frame_count, frame_step};
  return GlbSizeBound(model, info.generator, glb_layout(model, info, normals)).bytes(uint64_t(selection.written()));
}

std::unique_ptr<FrameSink> make_glb_sink(const OutputOptions& options, const fs::path& path,
                                         const TreeModel& model, const BakeInfo& info) {
  const FrameSelection selection{info.frame_start, info.frame_count, options.frame_step};
  const GlbSizeBound bound(model, info.generator, glb_layout(model, info, options.normals));
  const uint64_t bytes = bound.bytes(uint64_t(selection.written()));
  if (bytes > kGlbMaxBytes) {
    const uint64_t fits = bound.frames_within(kGlbMaxBytes);  // written frames
    char size[32];
    std::snprintf(size, sizeof size, "%.2f GiB", double(bytes) / double(1ull << 30));
    throw InputError(options.where() + ": the animated GLB " + path.string() + " would be " + size + " (" +
                      std::to_string(model.vertex_count()) + " vertices x " + std::to_string(selection.written()) +
                      " frames), over glTF's 4 GiB GLB limit; at most " + std::to_string(fits * uint64_t(options.frame_step)) +
                      " frames of this bake fit at frame_step " + std::to_string(options.frame_step) +
                      " (raise frame_step, shorten the bake, or use hdf5/pc2)");
  }
  check_float32_key_times(options, info, "glTF animations", true);
  return std::make_unique<GlbSink>(options, path, model, info);
}

}  // namespace treeanim
