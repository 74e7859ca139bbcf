// Boundary surface of a tet mesh: the faces used by exactly one tet, wound outward.
#pragma once

#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

#include <array>
#include <vector>

namespace stc {

struct BoundaryTriangle {
  Tri nodes;  // outward winding (right-hand rule normal points out of the tissue)
  int tet;    // the tet that owns the face
  int face;   // its local face index (see kTetFaces)
  bool cut;   // lies on a cut surface
};

struct BoundarySurface {
  std::vector<BoundaryTriangle> triangles;
  // Faces shared by more than two tets, or by two tets on the same side (tangled). Empty for
  // a valid mesh.
  int non_manifold_faces = 0;
};

BoundarySurface extract_boundary_surface(const TetMesh& mesh);

// A face of a tet under its sorted node triple.
struct KeyedFace {
  std::array<int, 3> key;  // its nodes, ascending
  int tet;
  int face;  // local face index (kTetFaces)
};

// Every face of every tet, ordered by key, then tet: the tets that share a face are neighbours
// in it. Linear time (a counting sort on the smallest node). Throws std::invalid_argument for
// a tet that refers to a node outside the mesh.
std::vector<KeyedFace> faces_by_key(const TetMesh& mesh);

// Nodes used by at least one boundary triangle, ascending.
std::vector<int> boundary_nodes(const BoundarySurface& surface);

// Every edge of the surface is used by exactly two triangles, in opposite directions.
bool is_closed_oriented_manifold(const BoundarySurface& surface);

}  // namespace stc
