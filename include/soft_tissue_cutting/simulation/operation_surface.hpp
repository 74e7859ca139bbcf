// The tissue's boundary surface after cuts, from the operation part alone (docs/DESIGN.md,
// per-step cost). Cuts change part 1 only, so the boundary triangles of part-2 tets and the
// faces shared by the two parts are kept from one whole-mesh extraction; after a cut only the
// part-1 tets (a few thousand at organ scale, of 70k+) are scanned again, and only the faces of
// the tets a cut changed are matched again (mesh/face_adjacency.hpp).
#pragma once

#include "soft_tissue_cutting/mesh/boundary_surface.hpp"
#include "soft_tissue_cutting/mesh/face_adjacency.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace stc {

class OperationSurface {
 public:
  // One whole-mesh extraction: operation_tet per tet, nonzero = part 1.
  void init(const TetMesh& mesh, const std::vector<std::uint8_t>& operation_tet);
  // A cut rewrote or appended the tets in `changed` (all of them part 1).
  void update(const TetMesh& mesh, const std::vector<int>& changed);
  // The whole boundary surface now (same triangles as extract_boundary_surface(mesh), part-2
  // triangles first).
  BoundarySurface current(const TetMesh& mesh) const;
  // Its part-2 triangles, the leading condensed_count() of current(), are the same from one
  // init to the next: which one this is (unique among all OperationSurfaces), their count, and
  // the triangles after them (non_manifold_faces: the whole surface's).
  long extraction() const { return extraction_; }
  size_t condensed_count() const { return condensed_.size(); }
  BoundarySurface operation_part(const TetMesh& mesh) const;
  // Part 1's face-connected pieces (as face_connected_pieces of the part-1 tets alone).
  std::vector<MeshPiece> part1_pieces(const TetMesh& mesh) const { return part1_.pieces(mesh); }

 private:
  TetFaceAdjacency part1_;  // which part-1 tets share each face

  std::vector<BoundaryTriangle> condensed_;  // boundary triangles owned by part-2 tets
  std::vector<std::array<int, 3>> shared_;   // sorted node triples of part 1 / part 2 faces
  int condensed_non_manifold_ = 0;
  long extraction_ = 0;  // 0: never extracted
};

// The tets of `tets` as a mesh of their own (same node numbering and rest positions, cut flags
// kept): for per-part queries (pieces, boundary). Positions are copied because the free-piece
// rule asks whether a piece's anchored nodes span a triangle (cutting/free_pieces.hpp).
TetMesh tet_subset(const TetMesh& mesh, const std::vector<int>& tets);

}  // namespace stc
