// Leaf meshes: the default quad, a custom mesh read with assimp, the grammar's '{ . }' outlines,
// or the meshes the turtle placed (cpfg surfaces, spheres, circles).
#include <Eigen/Geometry>
#include <assimp/DefaultIOSystem.h>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "common/errors.h"
#include "common/input_files.h"
#include "tree/tree_build_steps.h"

namespace treeanim {
namespace {

uint32_t point_count(const Skeleton& skeleton, size_t l) {
  return skeleton.leaf_polygon_offsets[l + 1] - skeleton.leaf_polygon_offsets[l];
}

// Leaf l's mesh triangles (0: it has none).
uint32_t mesh_triangles(const Skeleton& skeleton, size_t l) {
  return (skeleton.leaf_triangle_offsets[l + 1] - skeleton.leaf_triangle_offsets[l]) / 3;
}

// Leaf l uses its '{ . }' outline when it has a polygon and no triangles (fewer than 3 points
// enclose no area and fall back to the instanced shape).
uint32_t outline_points(const Skeleton& skeleton, size_t l) {
  const uint32_t n = point_count(skeleton, l);
  return n >= 3 && mesh_triangles(skeleton, l) == 0 ? n : 0;
}

// Area of a triangle mesh given as positions (3 x n) and triangles => m^2.
double mesh_area(const Eigen::Matrix3Xd& p, std::span<const uint32_t> triangles) {
  double area = 0;
  for (size_t t = 0; t < triangles.size(); t += 3) {
    const Eigen::Vector3d a = p.col(triangles[t]);
    area += 0.5 * (p.col(triangles[t + 1]) - a).cross(p.col(triangles[t + 2]) - a).norm();
  }
  return area;
}

// Appends one assimp mesh's triangles and vertices to the template being assembled.
void append_ai_mesh(const aiMesh& mesh, std::vector<Eigen::Vector3d>& points,
                    std::vector<Eigen::Vector2f>& uvs, std::vector<uint32_t>& triangles) {
  const uint32_t first = uint32_t(points.size());
  for (unsigned i = 0; i < mesh.mNumVertices; ++i) {
    const aiVector3D& v = mesh.mVertices[i];
    points.emplace_back(v.x, v.y, v.z);
    const bool has_uv = mesh.HasTextureCoords(0);
    uvs.emplace_back(has_uv ? mesh.mTextureCoords[0][i].x : 0.f,
                     has_uv ? mesh.mTextureCoords[0][i].y : 0.f);
  }
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines of the file carry no area
    for (unsigned k = 0; k < 3; ++k) triangles.push_back(first + face.mIndices[k]);
  }
}

// A scene's meshes, their node transforms applied => scaled about the origin so that their
// largest extent is 1 (left as they are when it is 0 or not finite: refused later).
void scale_to_unit_size(const aiScene& scene) {
  ai_real lo[3], hi[3];
  bool any = false;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m)
    for (unsigned v = 0; v < scene.mMeshes[m]->mNumVertices; ++v)
      for (int i = 0; i < 3; ++i) {
        const ai_real x = scene.mMeshes[m]->mVertices[v][i];
        lo[i] = any ? std::min(lo[i], x) : x;
        hi[i] = any ? std::max(hi[i], x) : x;
        any = any || i == 2;
      }
  if (!any) return;
  const double extent = std::max({double(hi[0]) - lo[0], double(hi[1]) - lo[1], double(hi[2]) - lo[2]});
  if (!(extent > 0) || !std::isfinite(extent)) return;
  const ai_real scale = ai_real(1 / extent);
  for (unsigned m = 0; m < scene.mNumMeshes; ++m)
    for (unsigned v = 0; v < scene.mMeshes[m]->mNumVertices; ++v) scene.mMeshes[m]->mVertices[v] *= scale;
}

// A PLY file (it starts "ply") whose header has no end_header line sends assimp's reader
// seeking round for ever (assimp 5.2): refused here, naming the file, before it is handed over.
void check_ply_header(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  std::string head(4, '\0');
  if (!in.read(head.data(), 4) || head.compare(0, 3, "ply") != 0 || (head[3] != '\n' && head[3] != '\r')) return;
  for (std::string line; std::getline(in, line);)
    if (line == "end_header" || line == "end_header\r") return;
  throw InputError(file + ": cannot read leaf mesh: a PLY file whose header has no end_header line (cut short?)");
}

// An imported scene => InputError naming `file` unless every point is finite and every face
// has corners, each a point of its mesh, a polygon of more than three of them none twice (the
// triangulation reads those; a repeat in a triangle or line only leaves it without area).
void check_ai_meshes(const aiScene& scene, const std::string& file) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[m];
    for (unsigned i = 0; i < mesh.mNumVertices; ++i) {
      const aiVector3D& v = mesh.mVertices[i];
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        throw InputError(file + ": leaf mesh point " + std::to_string(i) + " is not finite");
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      std::vector<unsigned> corners(face.mIndices, face.mIndices + face.mNumIndices);
      std::sort(corners.begin(), corners.end());
      if (corners.empty() || corners.back() >= mesh.mNumVertices ||
          (corners.size() > 3 && std::adjacent_find(corners.begin(), corners.end()) != corners.end()))
        throw InputError(file + ": leaf mesh face " + std::to_string(f) +
                         " has no corners, a corner past the last point or one corner twice");
    }
  }
}

}  // namespace

LeafTemplate default_leaf_template(const LeafOptions& options) {
  const double len = options.size, half_w = 0.5 * options.size * options.aspect;
  const double y0 = options.petiole;
  LeafTemplate t;
  t.positions.resize(3, 4);
  // base, right, tip, left: counter-clockwise seen from +z (the turtle's U).
  t.positions.col(0) << 0, y0, 0;
  t.positions.col(1) << half_w, y0 + 0.5 * len, 0;
  t.positions.col(2) << 0, y0 + len, 0;
  t.positions.col(3) << -half_w, y0 + 0.5 * len, 0;
  t.uvs.resize(2, 4);
  t.uvs << 0.5f, 1.f, 0.5f, 0.f,
           0.f, 0.5f, 1.f, 0.5f;
  t.triangles = {0, 1, 2, 0, 2, 3};
  t.attachment = 0;
  t.area = len * half_w;
  t.length = len;
  return t;
}

// assimp's own file access, each file it opens noted: the files a mesh names (a glTF's buffers,
// an OBJ's materials) are its inputs as much as the mesh, which no output may replace and whose
// bytes a bake's key holds.
class NotingFiles final : public Assimp::DefaultIOSystem {
 public:
  explicit NotingFiles(std::vector<std::filesystem::path>& files) : files_(files) {}
  Assimp::IOStream* Open(const char* file, const char* mode = "rb") override {
    Assimp::IOStream* stream = DefaultIOSystem::Open(file, mode);
    if (stream) {
      note_input_file(file);
      files_.push_back(std::filesystem::path(file).lexically_normal());
    }
    return stream;
  }

 private:
  std::vector<std::filesystem::path>& files_;
};

LeafTemplate load_leaf_template(const LeafOptions& options) {
  const std::string file = options.mesh->string();
  LeafTemplate t;
  Assimp::Importer importer;
  importer.SetIOHandler(new NotingFiles(t.files));  // the importer owns it
  // Normals and colours are dropped before joining so that vertices split only for shading
  // merge back: the simulation wants one particle per surface point.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS,
                              aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                  aiComponent_COLORS | aiComponent_BONEWEIGHTS |
                                  aiComponent_ANIMATIONS | aiComponent_LIGHTS |
                                  aiComponent_CAMERAS | aiComponent_MATERIALS);
  // What the file holds is checked before the triangulation reads it (the importer's own check
  // of what is left once the parts a leaf does not use are dropped, then check_ai_meshes): a
  // damaged file whose faces point past its vertices or whose polygons are cut short is refused
  // here, where the triangulation asserted or crashed on it.
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(file, error);
  if (!std::filesystem::exists(status)) throw InputError(file + ": cannot read leaf mesh: " + why_no_file(status, error));
  if (!std::filesystem::is_regular_file(status)) throw InputError(file + ": cannot read leaf mesh: not a regular file");
  check_ply_header(file);
  const aiScene* scene = importer.ReadFile(file, aiProcess_RemoveComponent);
  if (scene) scene = importer.ApplyPostProcessing(aiProcess_ValidateDataStructure);
  if (!scene || !scene->mRootNode)
    throw InputError(file + ": cannot read leaf mesh: " + importer.GetErrorString());
  check_ai_meshes(*scene, file);
  scene = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_PreTransformVertices);
  if (!scene || !scene->mRootNode)
    throw InputError(file + ": cannot read leaf mesh: " + importer.GetErrorString());
  // The mesh is joined at unit size: assimp joins vertices closer than 1e-5 in the file's
  // units, which took the corners of a leaf modelled 1e-5 across for one point; its size is
  // the scene's (leaf.size) anyway.
  scale_to_unit_size(*scene);
  scene = importer.ApplyPostProcessing(aiProcess_JoinIdenticalVertices);
  if (!scene || !scene->mRootNode)
    throw InputError(file + ": cannot read leaf mesh: " + importer.GetErrorString());
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2f> uvs;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) append_ai_mesh(*scene->mMeshes[m], points, uvs, t.triangles);
  if (t.triangles.empty()) throw InputError(file + ": leaf mesh has no triangles");
  t.positions.resize(3, Eigen::Index(points.size()));
  t.uvs.resize(2, Eigen::Index(uvs.size()));
  for (size_t i = 0; i < points.size(); ++i) {
    t.positions.col(Eigen::Index(i)) = points[i];
    t.uvs.col(Eigen::Index(i)) = uvs[i];
  }
  const double extent = (t.positions.rowwise().maxCoeff() - t.positions.rowwise().minCoeff()).maxCoeff();
  if (!(extent > 0)) throw InputError(file + ": leaf mesh has zero extent");
  if (!std::isfinite(extent)) throw InputError(file + ": leaf mesh reaches past any size (its nodes' transforms?)");
  t.positions *= options.size / extent;
  t.positions.row(1).array() += options.petiole;
  const Eigen::Vector3d petiole_base(0, options.petiole, 0);
  Eigen::Index nearest = 0;
  (t.positions.colwise() - petiole_base).colwise().squaredNorm().minCoeff(&nearest);
  t.attachment = uint32_t(nearest);
  t.area = mesh_area(t.positions, t.triangles);
  t.length = t.positions.row(1).maxCoeff() - t.positions.row(1).minCoeff();
  return t;
}

size_t leaf_vertex_count(const Skeleton& skeleton, const LeafTemplate& shape) {
  size_t n = 0;
  for (size_t l = 0; l < skeleton.leaf_count(); ++l) {
    const bool own = outline_points(skeleton, l) || mesh_triangles(skeleton, l);
    n += own ? point_count(skeleton, l) : size_t(shape.positions.cols());
  }
  return n;
}

size_t leaf_triangle_count(const Skeleton& skeleton, const LeafTemplate& shape) {
  size_t n = 0;
  for (size_t l = 0; l < skeleton.leaf_count(); ++l) {
    const uint32_t outline = outline_points(skeleton, l), mesh = mesh_triangles(skeleton, l);
    n += outline ? outline - 2 : mesh ? mesh : shape.triangles.size() / 3;
  }
  return n;
}

namespace {

// The turtle frame of leaf l as a rotation from the leaf frame (+y => H, -x => L, +z => U).
Eigen::Matrix3d leaf_frame(const Skeleton& skeleton, size_t l) {
  Eigen::Matrix3d r;
  r.col(0) = -skeleton.leaf_left[l];
  r.col(1) = skeleton.leaf_heading[l];
  r.col(2) = skeleton.leaf_up[l];
  return r;
}

// Instance of `shape` at leaf l, from vertex `first` and (with the surface) triangle slot `tri` on.
void write_instance(const Skeleton& skeleton, const TreeOptions& options, const LeafTemplate& shape,
                    size_t l, uint32_t first, bool surface, uint32_t*& tri, TreeModel& model) {
  const Eigen::Matrix3d frame = leaf_frame(skeleton, l) * skeleton.leaf_scale[l];
  const Eigen::Vector3d origin = skeleton.leaf_position[l] * options.scale;
  const Eigen::Index n = shape.positions.cols();
  model.rest_positions.middleCols(first, n) = (frame * shape.positions).colwise() + origin;
  if (!surface) return;
  model.uvs.middleCols(first, n) = shape.uvs;
  for (uint32_t i : shape.triangles) *tri++ = first + i;
}

// What the points of a leaf give its cluster: the vertex nearest the leaf position (the
// attachment) and the extent of their leaf-plane y (their v; the length, m).
struct LeafPoints {
  uint32_t attachment = 0;
  double length = 0;
};

// The n world points of leaf l (scene units) => vertices from `first` (m), with the surface
// their UVs, the leaf-plane coordinates (m).
LeafPoints write_points(const Skeleton& skeleton, const TreeOptions& options, size_t l, uint32_t n,
                        uint32_t first, bool surface, TreeModel& model) {
  const uint32_t p0 = skeleton.leaf_polygon_offsets[l];
  const Eigen::Vector3d origin = skeleton.leaf_position[l] * options.scale;
  const Eigen::Matrix3d to_leaf = leaf_frame(skeleton, l).transpose();
  double nearest = std::numeric_limits<double>::infinity();
  float v_lo = std::numeric_limits<float>::infinity(), v_hi = -v_lo;
  LeafPoints points{first, 0};
  for (uint32_t i = 0; i < n; ++i) {
    const Eigen::Vector3d p = skeleton.polygon_points[p0 + i] * options.scale;
    model.rest_positions.col(first + i) = p;
    const Eigen::Vector3d local = to_leaf * (p - origin);
    const Eigen::Vector2f uv(float(local.x()), float(local.y()));
    if (surface) model.uvs.col(first + i) = uv;
    v_lo = std::min(v_lo, uv.y());
    v_hi = std::max(v_hi, uv.y());
    const double d = (p - origin).squaredNorm();
    if (d < nearest) {
      nearest = d;
      points.attachment = first + i;
    }
  }
  points.length = double(v_hi - v_lo);
  return points;
}

// Outline of leaf l (n >= 3 points at `first`) => area (m^2); with the surface its triangles,
// fanned from its first point, wound so that its front faces the turtle's U.
double write_outline(const Skeleton& skeleton, size_t l, uint32_t n, uint32_t first, bool surface, uint32_t*& tri,
                     const TreeModel& model) {
  Eigen::Vector3d newell = Eigen::Vector3d::Zero();
  for (uint32_t i = 0; i < n; ++i)
    newell += model.rest_positions.col(first + i).cross(model.rest_positions.col(first + (i + 1) % n));
  const bool flip = newell.dot(skeleton.leaf_up[l]) < 0;
  if (surface)
    for (uint32_t i = 1; i + 1 < n; ++i) {
      *tri++ = first;
      *tri++ = first + (flip ? i + 1 : i);
      *tri++ = first + (flip ? i : i + 1);
    }
  return 0.5 * newell.norm();
}

// Mesh of leaf l (n points at `first`, its own triangles, wound by the turtle) => area (m^2),
// the sum of its triangles (a closed shape counts its whole surface); with the surface, its
// triangles.
double write_mesh(const Skeleton& skeleton, size_t l, uint32_t n, uint32_t first, bool surface, uint32_t*& tri,
                  const TreeModel& model) {
  const std::span<const uint32_t> own(skeleton.leaf_triangles.data() + skeleton.leaf_triangle_offsets[l],
                                      skeleton.leaf_triangle_offsets[l + 1] - skeleton.leaf_triangle_offsets[l]);
  if (surface)
    for (uint32_t i : own) *tri++ = first + i;
  return mesh_area(model.rest_positions.middleCols(first, n), own);
}

}  // namespace

LeafMeshes build_leaf_meshes(const Skeleton& skeleton, const TreeOptions& options,
                             const LeafTemplate& shape, const MeshCounts& counts, TreeModel& model) {
  const size_t L = skeleton.leaf_count();
  LeafMeshes leaves;
  leaves.vertex_offsets.resize(L + 1);
  leaves.attachment.resize(L);
  leaves.area.resize(L);
  leaves.length.resize(L);
  uint32_t next = uint32_t(counts.branch_vertices);
  const bool surface = model.uvs.cols() != 0;
  uint32_t* tri = surface ? model.triangles.data() + 3 * counts.branch_triangles : nullptr;
  for (size_t l = 0; l < L; ++l) {
    leaves.vertex_offsets[l] = next;
    const uint32_t outline = outline_points(skeleton, l);
    if (outline || mesh_triangles(skeleton, l)) {
      const uint32_t n = point_count(skeleton, l);
      const LeafPoints points = write_points(skeleton, options, l, n, next, surface, model);
      leaves.area[l] = outline ? write_outline(skeleton, l, n, next, surface, tri, model)
                               : write_mesh(skeleton, l, n, next, surface, tri, model);
      leaves.attachment[l] = points.attachment;
      leaves.length[l] = points.length;
      next += n;
    } else {
      write_instance(skeleton, options, shape, l, next, surface, tri, model);
      const double s = skeleton.leaf_scale[l];
      leaves.area[l] = shape.area * s * s;
      leaves.length[l] = shape.length * s;
      leaves.attachment[l] = next + shape.attachment;
      next += uint32_t(shape.positions.cols());
    }
    std::fill(model.vertex_segment.begin() + leaves.vertex_offsets[l], model.vertex_segment.begin() + next, -1);
    std::fill(model.vertex_leaf.begin() + leaves.vertex_offsets[l], model.vertex_leaf.begin() + next, int32_t(l));
  }
  leaves.vertex_offsets[L] = next;
  return leaves;
}

}  // namespace treeanim
