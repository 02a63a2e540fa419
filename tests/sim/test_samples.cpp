// hsm.particles "samples" (docs/solver.md, "Particles"): the samples keep each cluster's mass,
// centre and moment matrix; the skin places the rest mesh exactly and a rigid motion exactly;
// the solver on the samples moves the tree as on the vertices, deterministically, through
// detachment, sleep and a resume.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "grown_tree.h"
#include "same_state.h"
#include "sim/particle_model.h"
#include "sim/sample_skin.h"
#include "sim/simulator.h"

namespace treeanim {
namespace {

using testing::grown_tree;
using testing::gust_then_calm;
using testing::same_bytes;

constexpr double kSampleFrameDt = 1.0 / 24;

struct Moments {
  double mass = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();  // about the centre
};

Moments cluster_moments(const TreeModel& model, size_t c) {
  Moments m;
  for (uint32_t i = model.cluster_offsets[c]; i < model.cluster_offsets[c + 1]; ++i) {
    const uint32_t v = model.cluster_members[i];
    m.mass += model.vertex_mass[v];
    m.centre += model.vertex_mass[v] * model.rest_positions.col(v);
  }
  m.centre /= m.mass;
  for (uint32_t i = model.cluster_offsets[c]; i < model.cluster_offsets[c + 1]; ++i) {
    const uint32_t v = model.cluster_members[i];
    const Eigen::Vector3d d = model.rest_positions.col(v) - m.centre;
    m.second += model.vertex_mass[v] * d * d.transpose();
  }
  return m;
}

TEST(SampleModel, KeepsEachClustersMassCentreMomentsAndDragArea) {
  const TreeModel mesh = grown_tree(5, 1, 4);
  const TreeModel samples = sample_tree_model(mesh);
  ASSERT_EQ(samples.cluster_count(), mesh.cluster_count());
  ASSERT_EQ(samples.leaf_count(), mesh.leaf_count());
  EXPECT_LT(samples.vertex_count() * 3, mesh.vertex_count());
  for (size_t c = 0; c < mesh.cluster_count(); ++c) {
    SCOPED_TRACE("cluster " + std::to_string(c));
    const Moments a = cluster_moments(mesh, c), b = cluster_moments(samples, c);
    const double size = std::sqrt(a.second.trace() / a.mass) + 1e-12;
    EXPECT_NEAR(b.mass, a.mass, 1e-12 * a.mass);
    EXPECT_LT((b.centre - a.centre).norm(), 1e-9 * size);
    EXPECT_LT((b.second - a.second).norm(), 1e-9 * a.second.norm() + 1e-15);
    double area_a = 0, area_b = 0;
    for (uint32_t i = mesh.cluster_offsets[c]; i < mesh.cluster_offsets[c + 1]; ++i)
      area_a += mesh.vertex_drag_area[mesh.cluster_members[i]];
    for (uint32_t i = samples.cluster_offsets[c]; i < samples.cluster_offsets[c + 1]; ++i)
      area_b += samples.vertex_drag_area[samples.cluster_members[i]];
    EXPECT_NEAR(area_b, area_a, 1e-12 * area_a + 1e-18);
  }
  // The leaves' shared vertices and the extreme vertices are the mesh's own.
  for (size_t l = 0; l < mesh.leaf_count(); ++l)
    EXPECT_EQ(samples.rest_positions.col(samples.leaf_attachment_vertex[l]),
              mesh.rest_positions.col(mesh.leaf_attachment_vertex[l]));
  EXPECT_EQ(samples.rest_positions.rowwise().maxCoeff(), mesh.rest_positions.rowwise().maxCoeff());
  EXPECT_EQ(samples.rest_positions.rowwise().minCoeff(), mesh.rest_positions.rowwise().minCoeff());
}

// The samples of a mesh built without its surface, or of a mesh given up as they are drawn (a
// samples bake that writes nothing), are those of the whole mesh kept, to the bit.
TEST(SampleModel, AreTheSameFromABareMeshAndFromAMeshGivenUp) {
  const TreeModel mesh = grown_tree(5, 1, 4);
  const TreeModel kept = sample_tree_model(mesh);
  TreeModel given = mesh;
  const TreeModel from_given = sample_tree_model(std::move(given));
  EXPECT_EQ(given.vertex_count(), 0u);
  EXPECT_EQ(given.cluster_count(), 0u);
  EXPECT_TRUE(given.vertex_mass.empty() && given.cluster_members.empty() && given.segment_start.empty());
  TreeModel bare = grown_tree(5, 1, 4, MeshSurface::kOmitted);
  ASSERT_TRUE(bare.triangles.empty());
  const TreeModel from_bare = sample_tree_model(std::move(bare));
  EXPECT_EQ(kept.uvs.cols(), 0);
  EXPECT_TRUE(kept.triangles.empty());
  for (const TreeModel* other : {&from_given, &from_bare}) {
    EXPECT_TRUE(same_bytes(other->rest_positions, kept.rest_positions));
    EXPECT_EQ(other->vertex_mass, kept.vertex_mass);
    EXPECT_EQ(other->vertex_drag_area, kept.vertex_drag_area);
    EXPECT_EQ(other->vertex_anchored, kept.vertex_anchored);
    EXPECT_EQ(other->vertex_segment, kept.vertex_segment);
    EXPECT_EQ(other->vertex_leaf, kept.vertex_leaf);
    EXPECT_EQ(other->cluster_offsets, kept.cluster_offsets);
    EXPECT_EQ(other->cluster_members, kept.cluster_members);
    EXPECT_EQ(other->member_cluster, kept.member_cluster);
    EXPECT_EQ(other->cluster_kind, kept.cluster_kind);
    EXPECT_EQ(other->cluster_parent, kept.cluster_parent);
    EXPECT_EQ(other->cluster_length, kept.cluster_length);
    EXPECT_EQ(other->cluster_radius, kept.cluster_radius);
    EXPECT_EQ(other->leaf_cluster, kept.leaf_cluster);
    EXPECT_EQ(other->leaf_attachment_vertex, kept.leaf_attachment_vertex);
    EXPECT_EQ(other->segment_start, kept.segment_start);
    EXPECT_EQ(other->segment_radius_top, kept.segment_radius_top);
    EXPECT_EQ(other->segment_cluster, kept.segment_cluster);
  }
}

TEST(SampleSkin, PlacesTheRestMeshExactlyAndARigidMotionExactly) {
  const TreeModel mesh = grown_tree(4, 1, 4);
  const TreeModel samples = sample_tree_model(mesh);
  const SampleSkin skin(mesh, samples);
  Simulator simulator(samples, HsmOptions{}, WindOptions{}, kSampleFrameDt, 2);
  SimState state = simulator.initial_state(0);
  ClusterFrames frames;
  SimState out;
  skin.pose(state, true, frames, out);
  EXPECT_TRUE(same_bytes(out.positions, mesh.rest_positions));
  EXPECT_TRUE(out.velocities.isZero(0));
  // A turn about the root and a move, spinning at 0.3 rad/s about +Y: every vertex but the
  // anchored ones moves with it.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.3, 1, 0.1).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(0.1, -0.05, 0.3), spin(0, 0.3, 0);
  for (long s = 0; s < state.positions.cols(); ++s) {
    state.positions.col(s) = R * samples.rest_positions.col(s) + t;
    state.velocities.col(s) = spin.cross(state.positions.col(s) - t);
  }
  skin.pose(state, true, frames, out);
  double worst = 0, worst_speed = 0;
  for (long v = 0; v < out.positions.cols(); ++v) {
    if (mesh.vertex_anchored[v]) continue;
    const Eigen::Vector3d x = R * mesh.rest_positions.col(v) + t;
    worst = std::max(worst, (out.positions.col(v) - x).norm());
    worst_speed = std::max(worst_speed, (out.velocities.col(v) - spin.cross(x - t)).norm());
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(worst_speed, 1e-9);
}

// RMS over frames and vertices of |a - b|, and the RMS displacement from rest of `b`.
struct Distance {
  double rms = 0, largest = 0, displacement = 0;
};

TEST(Samples, MoveTheTreeAsTheVerticesDo) {
  const TreeModel mesh = grown_tree(5, 1, 4);
  const TreeModel samples = sample_tree_model(mesh);
  const SampleSkin skin(mesh, samples);
  const WindOptions wind = gust_then_calm(9, 1.5, 2.0);
  HsmOptions options;
  Simulator vertices(mesh, options, wind, kSampleFrameDt, 4);
  Simulator sampled(samples, options, wind, kSampleFrameDt, 4);
  SimState a = vertices.initial_state(0), b = sampled.initial_state(0), skinned;
  ClusterFrames frames;
  double diff2 = 0, disp2 = 0, largest = 0, largest_disp = 0;
  long long n = 0;
  for (int frame = 1; frame <= 48; ++frame) {
    vertices.advance_frame(a, frame);
    sampled.advance_frame(b, frame);
    skin.pose(b, false, frames, skinned);
    ASSERT_TRUE(skinned.positions.allFinite());
    for (long v = 0; v < a.positions.cols(); ++v) {
      const double d = (skinned.positions.col(v) - a.positions.col(v)).squaredNorm();
      const double u = (a.positions.col(v) - mesh.rest_positions.col(v)).squaredNorm();
      diff2 += d, disp2 += u, ++n;
      largest = std::max(largest, std::sqrt(d));
      largest_disp = std::max(largest_disp, std::sqrt(u));
    }
  }
  const double rms = std::sqrt(diff2 / n), displacement = std::sqrt(disp2 / n);
  ASSERT_GT(displacement, 1e-3);
  EXPECT_LT(rms, 0.05 * displacement) << "RMS " << rms << " m of " << displacement << " m";
  EXPECT_LT(largest, 0.25 * largest_disp) << largest << " m of " << largest_disp << " m";
}

// The mesh of a sampled bake with leaves that detach and islands that fall asleep, at a
// thread count, and of a bake resumed from a copy of its state.
Eigen::Matrix3Xd sampled_bake(int threads, int resume_at) {
  omp_set_num_threads(threads);
  const TreeModel mesh = grown_tree(4, 2, 2);
  const TreeModel samples = sample_tree_model(mesh);
  const SampleSkin skin(mesh, samples);
  HsmOptions options;
  options.leaf_detach_force = 0.02;
  options.precision = Precision::kFloat;
  const WindOptions wind = gust_then_calm(16, 0.5, 0.7);
  Simulator simulator(samples, options, wind, kSampleFrameDt, 3);
  SimState state = simulator.initial_state(0), skinned;
  ClusterFrames frames;
  Eigen::Matrix3Xd all(3, 0);
  for (int frame = 1; frame <= 60; ++frame) {
    if (frame == resume_at) {
      Simulator fresh(samples, options, wind, kSampleFrameDt, 3);
      SimState copy = state;
      fresh.advance_frame(copy, frame);
      simulator.advance_frame(state, frame);
      EXPECT_TRUE(same_bytes(copy.positions, state.positions));
    } else {
      simulator.advance_frame(state, frame);
    }
    skin.pose(state, true, frames, skinned);
    EXPECT_TRUE(skinned.positions.allFinite() && skinned.velocities.allFinite());
    // The frame an output writes, placed straight in float: each of these doubles rounded.
    const Eigen::Matrix3Xf rounded = skinned.positions.cast<float>(), speeds = skinned.velocities.cast<float>();
    Eigen::Matrix3Xf positions(3, rounded.cols()), velocities(3, rounded.cols());
    ClusterFrames again;
    skin.pose(state, again, positions.data(), velocities.data());
    EXPECT_TRUE(same_bytes(positions, rounded) && same_bytes(velocities, speeds)) << "frame " << frame;
    positions.setConstant(-1);
    skin.pose(state, again, positions.data(), nullptr);
    EXPECT_TRUE(same_bytes(positions, rounded)) << "frame " << frame << ", no velocities";
    Eigen::Matrix3Xd grown(3, all.cols() + skinned.positions.cols());
    grown << all, skinned.positions;
    all = grown;
  }
  EXPECT_LT(std::count(state.leaf_attached.begin(), state.leaf_attached.end(), 1), long(state.leaf_attached.size()));
  omp_set_num_threads(1);
  return all;
}

TEST(Samples, SameBytesForAnyThreadCountThroughDetachmentSleepAndResume) {
  const Eigen::Matrix3Xd one = sampled_bake(1, 0);
  EXPECT_TRUE(same_bytes(one, sampled_bake(2, 0)));
  EXPECT_TRUE(same_bytes(one, sampled_bake(2, 30)));
}

}  // namespace
}  // namespace treeanim
