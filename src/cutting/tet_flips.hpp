// Connectivity after a stroke (docs/DESIGN.md section 8, "Flip"): the smoothing moves nodes,
// but most corners of the thin tets a stroke leaves cannot move (on the curved skin, on several
// cut planes, locked). Their tets can still be replaced by better ones over the same cavity:
//
// - a 2-3 flip: two tets sharing a face become three around the edge joining their apexes,
// - an edge removal: the m tets around an edge become the 2 (m - 2) tets that pair the best
//   triangulation of their ring polygon with the edge's two ends (4 <= m <= 7: 4-4 to 7-10).
//
// Only across interior faces that are on no cut and around interior edges none of whose faces
// is, in cuttable tets: the boundary, every cut face and the volume stay as they were (no node
// moves), so what opened stays open and nothing closed opens. The flipped tets keep their
// indices and the rest are appended, as a bisection's children are (the 3-2 flip, which removes
// a tet, is not among them); the new tets' size class is the smallest of the cavity's.
#pragma once

#include "cutting/cut_state.hpp"
#include "cutting/vertex_insertion.hpp"
#include "soft_tissue_cutting/cutting/cut_result.hpp"

#include <vector>

namespace stc {

struct FlipCounts {
  int faces = 0;       // 2-3 flips
  int edges = 0;       // edge removals
  int insertions = 0;  // vertex insertions (vertex_insertion.hpp)
  int total() const { return faces + edges + insertions; }
};

// Replaces an insertion's cavity by its tets, the new node appended (its displacement
// interpolated in the host tet, docs/DESIGN.md eq. (21a)) and reported in result.new_nodes; the
// cavity's boundary faces keep their cut marks. Returns the new node; the changed and appended
// tets go to result.changed_tets. Counted in result.nodes_inserted only if `shape` (a node
// for the mesh's shape, not the cut's).
int apply_insertion(TetMesh& mesh, CutState& state, const VertexInsertion& insertion,
                    CutResult& result, bool shape);

// Replaces a star-from-a-corner's cavity by its tets (star_from_corner, vertex_insertion.hpp):
// no node is added; the cavity's boundary faces keep their cut marks. The changed and appended
// tets go to result.changed_tets.
void apply_star(TetMesh& mesh, CutState& state, const VertexInsertion& star, CutResult& result);

// Flips that raise the smallest dihedral angle of `tets` below CutOptions::smooth_below_deg
// (and of the tets the flips make), each by more than 0.05 deg over the tets it replaces and
// keeping every new tet above twice CutOptions::min_volume_fraction of its size class; where no
// flip reaches smooth_below_deg, a vertex insertion (CutOptions::insert_nodes) is a candidate
// too. The changed and appended tets go to result.changed_tets, an inserted node to
// result.new_nodes.
FlipCounts flip_thin_tets(TetMesh& mesh, CutState& state, const CutOptions& options,
                          const std::vector<int>& tets, CutResult& result);

}  // namespace stc
