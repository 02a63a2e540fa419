#pragma once
// The particles the solver simulates in hsm.particles "samples" (docs/solver.md, "Particles"):
// a TreeModel whose vertices are a few samples per cluster, standing for the mesh's vertices.
#include "tree/tree_model.h"

namespace treeanim {

// A mesh's TreeModel => the model of its samples: the same clusters, leaves and skeleton;
// vertices grouped by the clusters they are in (and their anchor, leaf and segment's cluster),
// each group of more than three (planar) or four vertices replaced by that many samples of
// equal mass and drag area that have the group's mass, centre and second moments; a leaf's
// shared vertex and the rest mesh's extreme vertices along each axis kept as they are, so the
// chain's joints, the tree's height and size are the mesh's. Every cluster then has its
// vertices' mass, centre and moment matrix A_qq, and its air load's sum and moment. The result
// has no surface (MeshSurface::kOmitted); it is validated.
TreeModel sample_tree_model(const TreeModel& mesh);
// The same samples from a mesh nothing reads afterwards: its arrays go back as soon as the
// samples have read them, so the two models are never whole together. The mesh is left empty.
TreeModel sample_tree_model(TreeModel&& mesh);

}  // namespace treeanim
