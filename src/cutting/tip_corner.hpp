// The tip's corner at a stroke's end (docs/DESIGN.md section 8, "The tip's corner", eqs. (19d),
// (19d')).
// The cut's border runs along the tip's path and, once the blade stops, along its front; both
// are conformed where they cross the tets' faces. Where they meet, the tissue is often one tet
// whose edges lie almost in the blade's plane (a fan of tets around an edge nearly on it): no
// crossing lies near the corner, and the opened surface stops an element short of where the
// tip stopped (the thigh's curved tilted 3 mm stroke: 4.2 mm, 1.5 x the Hausdorff tolerance).
// So, once the stroke's end has opened what it can, where no opened face comes within a front
// margin of the tip's last position, a node is put there - inside the cavity of tets the
// corner's triangle passes through, joined to every face of its boundary (vertex_insertion.hpp)
// - or, where that makes tets too thin, a node of the cut already within that margin becomes
// the corner (the cavity retriangulated as its star, eq. (19d')); the triangle from it to the
// nearest edge of the cut's border facing it is marked. Its corners all lie on the border, so it
// is opened as the stroke's other such marks are (closed_marks.hpp; finish_stroke).
#pragma once

#include "cutting/cut_state.hpp"
#include "soft_tissue_cutting/cutting/cut_result.hpp"

#include <array>
#include <vector>

namespace stc {

// Fills the corner at `tip` (rest coordinates) of the cut whose last band is `band` (its plane:
// the band's tip-side triangle), as above, where the shape guards allow it (every new tet's
// smallest dihedral angle at least CutOptions::split_min_dihedral_deg and its volume above
// twice min_volume_fraction of its size class). Returns the corner's node - the one added, or
// the node of the cut that became it (CutOptions::tip_corner_from_node) - or -1. The changed
// tets go to result.changed_tets, an added node to result.new_nodes.
int fill_tip_corner(TetMesh& mesh, CutState& state, const Vec3& tip,
                    const std::vector<std::array<Vec3, 3>>& band, const CutOptions& options,
                    CutResult& result);

}  // namespace stc
