#pragma once
// The shapes the turtle draws as leaves besides the tree's own leaf: a cpfg surface (~id), a
// sphere (@O) and a disc (@o, @c). Built once, before the turtle runs; read-only afterwards.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "lsystem/surface_file.h"

namespace treeanim {

// A triangle mesh in the leaf frame of docs/tree.md (+x = -L, +y = H, +z = U), scene units at
// scale 1, its attachment point (a surface's contact point, a sphere's or disc's centre) at
// the origin.
struct LeafShape {
  char id = 0;                               // the letter of ~id; 0 for the sphere and the disc
  std::vector<Eigen::Vector3d> points;       // (n) scene units
  std::vector<uint32_t> triangles;           // (t*3) ids into points, counter-clockwise seen from the front (+z on the whole)
  Eigen::Vector3d end = Eigen::Vector3d::Zero();  // scene units: where the turtle stands after drawing it
};

// surface, the view line's scale, quads per patch along s and t (1 ... 10) => its shape: the
// contact point at the origin, HEADING along +y, UP along +z, SIZE drawn `scale` long, each
// patch a grid of (s+1) x (t+1) points, points shared by patches welded into one.
LeafShape surface_shape(const BezierSurface& surface, char id, double scale, int s_quads, int t_quads);

// A sphere of diameter 1: an octahedron (6 points, 8 triangles), its -y pole first.
const LeafShape& sphere_shape();
// A disc of diameter 1 in the x-y plane (the turtle's HL plane): the centre, then 8 rim points.
const LeafShape& disc_shape();

}  // namespace treeanim
