// The bytes each format's output will take, estimated before baking (formats/output_estimate.h).
#include "formats/output_estimate.h"

#include <gtest/gtest.h>

#include "output/output_formats.h"

namespace treeanim {
namespace {

TEST(OutputEstimate, SizeEstimatesPerFormat) {
  // 100 vertices, 50 triangles, 7 clusters, 10 frames written every 3rd: 4 frames of 1200 bytes of vectors.
  auto bytes = [](const char* format, auto&& set) {
    OutputOptions o;
    o.format = find_output_format(format);
    o.frame_step = 3;
    set(o);
    return estimated_output_bytes(o, 100, 50, 7, 10);
  };
  auto plain = [](OutputOptions&) {};
  auto with_normals = [](OutputOptions& o) { o.normals = true; };
  // What each writes once: the rest mesh (an HDF5's 36 bytes a vertex and 12 a triangle; a
  // GLB's 45 and 12; an OBJ file's lines), a skinned output's weights and joints.
  const double hdf5_mesh = 36 * 100 + 12 * 50 + 32768, glb_mesh = 45 * 100 + 12 * 50, usd_mesh = 40 * 100 + 36 * 50;
  const double obj_file = 54 * 100 + (2 + 3 * 2 * 4) * 50, obj_normals_file = 92 * 100 + (2 + 3 * 3 * 4) * 50;
  EXPECT_EQ(bytes("hdf5", plain), 4800 + hdf5_mesh);
  EXPECT_EQ(bytes("hdf5", [](OutputOptions& o) { o.quantize = 1e-3, o.velocities = o.normals = true; }),
            12000 + hdf5_mesh);
  EXPECT_EQ(bytes("obj", plain), 5 * obj_file);  // four frames and the rest OBJ
  EXPECT_EQ(bytes("obj", with_normals), 5 * obj_normals_file);
  EXPECT_EQ(bytes("gltf", plain), 4 * (1200 + 20 * 100 + 12 * 50 + 2048));  // the whole mesh in each frame's file
  EXPECT_EQ(bytes("glb", with_normals), 9600 + glb_mesh);
  for (const char* format : {"pc2", "mdd"}) EXPECT_EQ(bytes(format, with_normals), 9600 + obj_file) << format;
  EXPECT_EQ(bytes("vat", plain), 12800 + glb_mesh);
  EXPECT_EQ(bytes("vat", [](OutputOptions& o) { o.vat_half = true; }), 6400 + glb_mesh);
  EXPECT_EQ(bytes("skinned_glb", plain), 4 * 28 * 7 + glb_mesh + 24 * 100 + 620 * 7);  // a joint per cluster
  EXPECT_EQ(bytes("skinned_glb", [](OutputOptions& o) { o.max_joints = 5; }), 4 * 28 * 5 + glb_mesh + 24 * 100 + 620 * 5);
  EXPECT_EQ(bytes("usd", plain), 4 * 36 * 100 + usd_mesh);
  EXPECT_EQ(bytes("usd", with_normals), 4 * (36 + 38) * 100 + usd_mesh);
  EXPECT_EQ(bytes("usd", [](OutputOptions& o) { o.skinned = true; }), 4 * 96 * 7 + usd_mesh + 24 * 100 + 320 * 7);
  // The page's whole size as its sink plans it (the viewer, about 0.6 MB, included), at most its limit.
  const double page = bytes("html", [](OutputOptions& o) { o.max_page_bytes = 2 << 20; });
  EXPECT_GT(page, 4 * 1600 + 500000);
  EXPECT_LT(page, 2 << 20);
  OutputOptions big;
  big.format = find_output_format("html");
  big.max_page_bytes = 2 << 20;
  EXPECT_EQ(estimated_output_bytes(big, 100000, 200000, 7, 1000), double(2 << 20)) << "reduced to fit";
}

}  // namespace
}  // namespace treeanim
