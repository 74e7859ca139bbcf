// Pieces of tissue a cut has severed from everything that holds the body in place.
//
// Policy the simulation applies (docs/SCENE.md "Cut invariants": "neither breaks the solver nor
// disappears silently"): a free piece is KEPT in the mesh and HELD at its current displacement -
// its nodes are treated as fixed (Dirichlet, value = their displacement when it came free) from
// then on, so K stays positive definite on the remaining free DOF and the piece stays visible
// where it was. It is never removed and never left singular; the simulation reports it.
#pragma once

#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

#include <vector>

namespace stc {

// Connected components of the mesh, tets connected when they share a node (a shared face
// or edge implies a shared node), in order of their smallest tet.
std::vector<MeshPiece> mesh_pieces(const TetMesh& mesh);

// Components connected by shared FACES, in order of their smallest tet.
std::vector<MeshPiece> face_connected_pieces(const TetMesh& mesh);

// The smallest of `pieces` that has `node` (a node shared by several through a hinge belongs
// to each); nullptr if none has it.
const MeshPiece* smallest_piece_with_node(const std::vector<MeshPiece>& pieces, int node);
// The answer points into `pieces`: never into a temporary.
const MeshPiece* smallest_piece_with_node(std::vector<MeshPiece>&& pieces, int node) = delete;

// The pieces not held rigidly: components connected by shared FACES (a piece hanging on by a
// node or an edge can rotate about it) with fewer than three non-collinear anchored nodes
// (anchored: per node, e.g. fixed or interface nodes).
std::vector<MeshPiece> free_pieces(const TetMesh& mesh, const std::vector<std::uint8_t>& anchored);
// The same for face-connected `pieces` already found (mesh/face_adjacency.hpp).
std::vector<MeshPiece> free_pieces(std::vector<MeshPiece> pieces, const TetMesh& mesh,
                                   const std::vector<std::uint8_t>& anchored);

}  // namespace stc
