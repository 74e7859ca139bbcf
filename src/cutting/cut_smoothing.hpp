// Shape after a stroke, not only size (docs/DESIGN.md section 8, "Smooth"): a bisection at
// t = 0.1 leaves a child whose dihedral angle at the opposite edge is about a tenth of the
// parent's, and cuts through the same region again make it thinner still. When the next
// stroke begins, the nodes of the tets the last one left below CutOptions::smooth_below_deg
// that may move (node_moves.hpp, how_node_may_move: inside their stars, within a flat fan of
// boundary faces, or along the crease of two flat fans) are moved to raise the smallest dihedral
// angle of their star (a local search, eq. (20b)). Not while a stroke goes on: its next bands are
// split and marked against the nodes where they are (a node moved near the blade's path changes
// what opens). No surface moves and the volume stays exact; the moved nodes and their stars' tets
// go to the CutResult like a relocation's.
#pragma once

#include "cutting/cut_state.hpp"
#include "soft_tissue_cutting/cutting/cut_result.hpp"

namespace stc {

// When the next stroke begins (its first cut_triangles, before it splits anything): the tets
// the last stroke changed (CutState::stroke_tets), which are then forgotten.
void smooth_last_stroke(TetMesh& mesh, CutState& state, const CutOptions& options,
                        CutResult& result);

}  // namespace stc
