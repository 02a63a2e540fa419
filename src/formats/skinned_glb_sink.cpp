// Skinned glTF ("skinned_glb", docs/outputs.md "Skinned glTF"): the rest mesh bound to one joint
// per cluster (or per limb, option max_joints), and per joint a translation and a rotation key
// per written frame, fitted so that the skinned mesh follows the bake (formats/skin_track.h). The RMS
// and largest error of the skinned mesh against the bake, relative to the bake's RMS
// displacement, go into the asset's extras ("skinning") and the run's summary. Written with tinygltf at the
// end: the keys of every frame are kept until then (28 bytes per joint and frame).
#include <tiny_gltf.h>

#include <algorithm>
#include <limits>

#include "common/errors.h"
#include "formats/frame_sink.h"
#include "formats/glb_size.h"
#include "formats/gltf_mesh.h"
#include "formats/sink_factories.h"
#include "formats/rest_positions_f32.h"
#include "formats/skin_fit.h"
#include "formats/skin_track.h"
#include "formats/vertex_normals.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

class SkinnedGlbSink final : public FrameSink {
 public:
  SkinnedGlbSink(const OutputOptions& options, fs::path path, const TreeModel& model, const BakeInfo& info)
      : path_(std::move(path)), model_(model), info_(info),
        selection_{info.frame_start, info.frame_count, options.frame_step},
        skin_(build_skin(model, options.max_joints > 0 ? options.max_joints : model.cluster_count())) {
    const uint64_t bytes = skinned_glb_bytes(model, skin_.joint_count(), uint64_t(selection_.written()));
    if (bytes > kGlbMaxBytes)
      throw InputError(options.where() + ": the skinned GLB " + path_.string() + " would pass glTF's 4 GiB GLB limit (" +
                        std::to_string(skin_.joint_count()) + " joints x " + std::to_string(selection_.written()) +
                        " frames); lower max_joints, raise frame_step or shorten the bake");
  }

  std::vector<SummaryFile> summary_paths() const override { return {{path_}}; }

  void begin() override {
    temporary_ = staged_.stage(path_);
    rest_ = rest_positions_f32(model_);
  }

  void write(const FrameData& frame) override {
    add_skin_frame(skin_, model_, frame.positions.data(), frame.cluster_motions, frame.time, track_);
  }

  void finish() override {
    error_ = skin_error(track_, model_.vertex_count());
    tinygltf::Model gltf = assemble();
    write_glb(gltf, temporary_, path_);
  }

  std::string report() const override { return skin_error_report(error_, skin_.joint_count()); }

 private:
  tinygltf::Model assemble() const {
    tinygltf::Model gltf;
    GltfBuilder add(gltf);
    const size_t n = model_.vertex_count(), joints = skin_.joint_count(), frames = track_.times.size();
    std::map<std::string, int> attributes;
    attributes["POSITION"] = add.floats(rest_, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER);
    set_bounds(gltf, attributes["POSITION"], rest_, 3);
    attributes["NORMAL"] = add.floats(rest_normals(model_), TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER);
    std::vector<float> weights(4 * n);
    std::vector<uint16_t> joint_ids(4 * n);
    for (size_t v = 0; v < n; ++v) {
      for (size_t k = 0; k < 4; ++k) {
        joint_ids[4 * v + k] = skin_.vertex_joints[v][k];
        weights[4 * v + k] = skin_.vertex_weights[v][k];
      }
    }
    attributes["TEXCOORD_0"] = add.floats(gltf_uvs(model_), TINYGLTF_TYPE_VEC2, 2, TINYGLTF_TARGET_ARRAY_BUFFER);
    attributes["JOINTS_0"] = add.accessor(joint_ids.data(), 2 * joint_ids.size(), TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                          n, TINYGLTF_TYPE_VEC4, TINYGLTF_TARGET_ARRAY_BUFFER);
    attributes["WEIGHTS_0"] = add.floats(weights, TINYGLTF_TYPE_VEC4, 4, TINYGLTF_TARGET_ARRAY_BUFFER);
    add_tree_mesh(add, model_, info_, attributes);

    // Node 0 holds the skinned mesh; nodes 1 + j are the joints, at their rest pivots.
    tinygltf::Node mesh_node;
    mesh_node.name = "tree";
    mesh_node.mesh = 0;
    mesh_node.skin = 0;
    gltf.nodes.push_back(mesh_node);
    tinygltf::Skin skin;
    skin.name = "clusters";
    std::vector<float> inverse_binds(16 * joints, 0.0f);
    tinygltf::Value::Array frame_errors;
    for (double error : track_.frame_rms_error) frame_errors.emplace_back(error);
    tinygltf::Scene scene;
    scene.nodes.push_back(0);
    for (size_t j = 0; j < joints; ++j) {
      tinygltf::Node joint;
      joint.name = "joint_" + std::to_string(j);
      const Eigen::Vector3d& pivot = skin_.joint_pivot[j];
      const int32_t parent = skin_.joint_parent[j];
      const Eigen::Vector3d local = parent < 0 ? pivot : Eigen::Vector3d(pivot - skin_.joint_pivot[size_t(parent)]);
      joint.translation = {local.x(), local.y(), local.z()};
      gltf.nodes.push_back(joint);
      skin.joints.push_back(int(1 + j));
      if (parent < 0) scene.nodes.push_back(int(1 + j));
      for (int d = 0; d < 4; ++d) inverse_binds[16 * j + size_t(5 * d)] = 1.0f;  // column-major T(-pivot)
      for (int a = 0; a < 3; ++a) inverse_binds[16 * j + 12 + size_t(a)] = float(-pivot[a]);
    }
    for (size_t j = 0; j < joints; ++j)
      if (skin_.joint_parent[j] >= 0) gltf.nodes[size_t(1 + skin_.joint_parent[j])].children.push_back(int(1 + j));
    skin.inverseBindMatrices = add.floats(inverse_binds, TINYGLTF_TYPE_MAT4, 16);
    // In the asset's extras: tinygltf writes no skin extras.
    gltf.asset.extras = tinygltf::Value(tinygltf::Value::Object{{"skinning", tinygltf::Value(tinygltf::Value::Object{
        {"skinning_error_rms", tinygltf::Value(error_.relative_rms)},
        {"skinning_error_max", tinygltf::Value(error_.relative_max)},
        {"skinning_error_relative_to", tinygltf::Value(std::string("the bake's RMS displacement from rest"))},
        {"rms_displacement_m", tinygltf::Value(error_.rms_displacement)},
        {"rms_error_m", tinygltf::Value(error_.rms_error)},
        {"largest_error_m", tinygltf::Value(track_.largest_error)},
        {"frame_rms_error_m", tinygltf::Value(frame_errors)},
        {"clusters", tinygltf::Value(int(model_.cluster_count()))},
        {"joints", tinygltf::Value(int(joints))}})}});
    gltf.skins.push_back(skin);

    if (frames > 0) {
      tinygltf::Animation animation;
      animation.name = "wind";
      // A loop closes with the first frame's keys again at the loop's end.
      std::vector<float> times = track_.times;
      if (info_.loop) times.push_back(float(info_.loop_end_time));
      const int input = add.floats(times, TINYGLTF_TYPE_SCALAR, 1);
      set_bounds(gltf, input, times, 1);
      std::vector<float> keys;
      for (size_t j = 0; j < joints; ++j) {
        for (const auto& [path, width] : {std::pair{"translation", 3}, std::pair{"rotation", 4}}) {
          const std::vector<float>& all = width == 3 ? track_.translations : track_.rotations;
          keys.clear();
          for (size_t k = 0; k < times.size(); ++k) {
            const size_t f = k % frames;
            keys.insert(keys.end(), all.begin() + long((f * joints + j) * size_t(width)),
                        all.begin() + long((f * joints + j + 1) * size_t(width)));
          }
          if (width == 4 && times.size() > frames) {  // the closing rotation the short way, as every key
            float* closing = keys.data() + 4 * frames;
            float dot = 0;
            for (int c = 0; c < 4; ++c) dot += closing[c] * closing[c - 4];
            if (dot < 0)
              for (int c = 0; c < 4; ++c) closing[c] = -closing[c];
          }
          tinygltf::AnimationSampler sampler;
          sampler.input = input;
          sampler.output = add.floats(keys, width == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4, width);
          sampler.interpolation = "LINEAR";
          animation.samplers.push_back(sampler);
          tinygltf::AnimationChannel channel;
          channel.sampler = int(animation.samplers.size() - 1);
          channel.target_node = int(1 + j);
          channel.target_path = path;
          animation.channels.push_back(channel);
        }
      }
      gltf.animations.push_back(animation);
    }
    gltf.scenes.push_back(scene);
    gltf.defaultScene = 0;
    gltf.asset.version = "2.0";
    gltf.asset.generator = info_.generator;
    return gltf;
  }

  fs::path path_;
  fs::path temporary_;
  const TreeModel& model_;
  BakeInfo info_;
  FrameSelection selection_;
  Skin skin_;
  std::vector<float> rest_;                          // (N*3) m, the bind pose
  SkinTrack track_;                                  // every written frame's keys and errors
  SkinError error_;                                  // after finish()
};

}  // namespace

uint64_t skinned_glb_bytes(const TreeModel& model, size_t joints, uint64_t frames) {
  const uint64_t n = model.vertex_count(), t = model.triangle_count(), j = joints;
  constexpr uint64_t kJsonPerJoint = 1024, kJsonFixed = 4096;  // generous: nodes, samplers, channels, accessors
  // A frame's RMS error in the extras: a double at its longest and a comma.
  constexpr uint64_t kJsonPerFrame = 25;
  const uint64_t keys = frames + 1;  // a loop's closing key
  return kJsonFixed + kJsonPerJoint * j + kJsonPerFrame * frames + 12 * t + n * (12 + 12 + 8 + 8 + 16 + 12) + 64 * j +
         4 * keys + 28 * keys * j + 8 * (2 * j + 16);
}

std::unique_ptr<FrameSink> make_skinned_glb_sink(const OutputOptions& options, const fs::path& path,
                                                 const TreeModel& model, const BakeInfo& info) {
  check_float32_key_times(options, info, "glTF animations", true);
  return std::make_unique<SkinnedGlbSink>(options, path, model, info);
}

}  // namespace treeanim
