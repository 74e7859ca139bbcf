// Simple measures of the cut surface, for the cutting and simulation tests (a test helper, not part
// of tissue_core).
#pragma once

#include "soft_tissue_cutting/mesh/tet_mesh.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"

#include <cstdint>
#include <vector>

namespace stc::test {

// Total area (rest configuration) of the boundary triangles marked as cut. An opened cut of
// area A contributes 2 A (one triangle on each lip).
double open_cut_area(const TetMesh& mesh);

// Number of cut faces still closed (marked, shared by two tets): a crack front waiting.
int closed_cut_faces(const TetMesh& mesh);

// Number of tets whose smallest dihedral angle is under `below_deg` degrees.
int thin_tets(const TetMesh& mesh, double below_deg = 5.0);

// The shapes of the tets `selected` flags (per tet; empty: all): their smallest dihedral angle
// and how many lie under `below_deg` degrees.
struct TetShapes {
  double least = 180;
  int thin = 0;
};
TetShapes tet_shapes(const TetMesh& mesh, const std::vector<std::uint8_t>& selected = {},
                     double below_deg = 5.0);

// Wedges of tissue sharper than `below_deg` degrees: edges whose tets' dihedral angles at the
// edge sum to less than that (a boundary edge where two cut walls, or a wall and the skin, meet
// at that angle; an interior edge's sum is 360 deg). The tets around such an edge share that
// angle between them, so no remeshing of the surface as it is lifts them above it: only a cut
// that does not make the wedge (docs/DESIGN.md section 8, "Where bisection stops").
int sharp_wedges(const TetMesh& mesh, double below_deg = 5.0);

// The hybrid matrix without the rows and columns of the DOFs of held nodes (`held_node`: one
// flag per mesh node; the nodes of free pieces): the block that must stay SPD after a cut.
SparseMatrix free_block(const HybridModel& model, const std::vector<std::uint8_t>& held_node);

}  // namespace stc::test
