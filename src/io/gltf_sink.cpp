// glTF sequence through assimp's "glb2" exporter: one self-contained .glb per written frame
// ("<name>.%04d.glb"), mesh with positions, UVs (and normals when asked) and the shared triangle list.
#include <assimp/Exporter.hpp>
#include <assimp/material.h>
#include <assimp/scene.h>

#include "common/errors.h"
#include "io/frame_sink.h"
#include "io/staged_files.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

// The rest mesh as an aiScene (one node, one mesh, one default material: assimp's glTF 2
// exporter dereferences the mesh's material, so a scene without one cannot be exported).
std::unique_ptr<aiScene> make_scene(const TreeModel& model, bool with_normals) {
  auto scene = std::make_unique<aiScene>();
  scene->mRootNode = new aiNode("tree");
  scene->mRootNode->mNumMeshes = 1;
  scene->mRootNode->mMeshes = new unsigned[1]{0};
  auto* material = new aiMaterial();
  const aiString material_name("bark");
  material->AddProperty(&material_name, AI_MATKEY_NAME);
  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial*[1]{material};

  auto* mesh = new aiMesh();
  mesh->mName = aiString("tree");
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh->mMaterialIndex = 0;
  const unsigned n = unsigned(model.vertex_count());
  mesh->mNumVertices = n;
  mesh->mVertices = new aiVector3D[n];
  mesh->mTextureCoords[0] = new aiVector3D[n];
  mesh->mNumUVComponents[0] = 2;
  if (with_normals) mesh->mNormals = new aiVector3D[n];
  for (unsigned v = 0; v < n; ++v) {
    mesh->mVertices[v] = aiVector3D(float(model.rest_positions(0, v)), float(model.rest_positions(1, v)),
                                    float(model.rest_positions(2, v)));
    // assimp keeps OBJ's convention (v up) and flips v itself when writing glTF.
    mesh->mTextureCoords[0][v] = aiVector3D(model.uvs(0, v), model.uvs(1, v), 0.0f);
  }
  mesh->mNumFaces = unsigned(model.triangle_count());
  mesh->mFaces = new aiFace[mesh->mNumFaces];
  for (unsigned t = 0; t < mesh->mNumFaces; ++t) {
    aiFace& face = mesh->mFaces[t];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3];
    for (int corner = 0; corner < 3; ++corner) face.mIndices[corner] = model.triangles[3 * t + corner];
  }
  scene->mNumMeshes = 1;
  scene->mMeshes = new aiMesh*[1]{mesh};
  return scene;
}

class GltfSink final : public FrameSink {
 public:
  GltfSink(const OutputOptions& options, const fs::path& path, const TreeModel& model, const BakeInfo& info)
      : pattern_(sequence_pattern(path, ".glb", options.pointer)), model_(model), normals_(options.normals),
        selection_{info.frame_start, info.frame_count, options.frame_step} {}

  void for_each_target(const std::function<void(const fs::path&)>& visit) const override {
    for (long long k = 0; k < selection_.written(); ++k) visit(pattern_.frame(selection_.start + k * selection_.step));
  }

  std::vector<fs::path> summary_paths() const override {
    if (selection_.written() == 0) return {};
    return {pattern_.frame(selection_.start)};
  }

  void begin() override { scene_ = make_scene(model_, normals_); }

  void write(const FrameData& frame) override {
    aiMesh* mesh = scene_->mMeshes[0];
    for (unsigned v = 0; v < mesh->mNumVertices; ++v)
      mesh->mVertices[v] = aiVector3D(frame.positions[3 * v], frame.positions[3 * v + 1], frame.positions[3 * v + 2]);
    if (normals_)
      for (unsigned v = 0; v < mesh->mNumVertices; ++v)
        mesh->mNormals[v] = aiVector3D(frame.normals[3 * v], frame.normals[3 * v + 1], frame.normals[3 * v + 2]);
    const fs::path target = pattern_.frame(frame.frame);
    const fs::path temporary = staged_.stage(target);
    if (exporter_.Export(scene_.get(), "glb2", temporary.string()) != aiReturn_SUCCESS)
      throw OutputError(target.string() + ": assimp could not write the glTF frame: " +
                        exporter_.GetErrorString());
  }


 private:
  SequencePattern pattern_;
  const TreeModel& model_;
  bool normals_;  // NORMAL in every frame
  FrameSelection selection_;
  std::unique_ptr<aiScene> scene_;  // rest mesh, positions replaced per frame
  Assimp::Exporter exporter_;
};

}  // namespace

std::unique_ptr<FrameSink> make_gltf_sink(const OutputOptions& options, const fs::path& path,
                                          const TreeModel& model, const BakeInfo& info) {
  return std::make_unique<GltfSink>(options, path, model, info);
}

}  // namespace treeanim
