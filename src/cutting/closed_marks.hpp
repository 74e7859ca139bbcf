// Closed marks at a stroke's end (docs/DESIGN.md section 8, "Closed marks"). A marked face opens
// when one of its corners is duplicated, and a corner is duplicated only when the marked faces
// around it close into a fan (separation.hpp). A mark whose three corners all lie on the cut
// surface's border - a strip one face wide along the tip's path or the front, a face alone in a
// corner between them - therefore stays closed, and while the blade moves on, later marks
// usually complete the fans around it. When the stroke ends nothing comes later: such a mark
// would stay a hole in the opened surface at the tip's path or the front. So it gets a corner
// that is not on the border: a node at the midpoint of its edge that another mark shares (the
// node's fan is then those marks' halves), or, for a face alone or one whose shared edge the
// guards keep whole, at its centre (two midpoint splits), and the marks are separated again;
// then what opened walls still hold shut, up to CutOptions::opening_rounds times. Only marks along
// the blade's own sweep (CutState::blade_sweep), with a shape guard of at least 5 deg on these
// splits.
#pragma once

#include "cutting/cut_state.hpp"
#include "soft_tissue_cutting/cutting/cut_result.hpp"

namespace stc {

// Splits the closed marked faces of `tets` (the stroke's tets) as above, where the volume and
// shape guards allow (CutOptions), and opens what that lets open. Returns the nodes added.
int open_closed_marks(TetMesh& mesh, CutState& state, const std::vector<int>& tets,
                      const CutOptions& options, CutResult& result);

}  // namespace stc
