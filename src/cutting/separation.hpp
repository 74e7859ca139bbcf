// Opening marked cut faces (step d-e of the cut): a node whose tet star falls apart into k
// pieces when the marked faces are removed from its adjacency is duplicated k - 1 times.
//
// At a crack front the star stays connected through the unmarked faces ahead of the cut, so
// the front stays closed and the marks wait for the next sweep to continue the cut. Before
// anything is changed the planned result is checked: a locked node that would be duplicated
// gets the still-closed marked faces around it unmarked. An edge that would end up in more
// than two boundary triangles (a new mark attached to an opened wall along an edge whose ends
// stay whole: a tilted blade's crease on a curved path) first has the nodes whose duplication
// puts it there left whole this time - the third corners of the closed marks on it, and its
// own ends - so their marks stay closed until later marks complete the surface around them;
// only when none is left to hold back are the closed marks around it unmarked. Either way the
// plan is redone. Holding back only shrinks the plan and dropping closed marks only ever
// returns towards the previous (valid) state, so the loop ends with a closed 2-manifold.
// First, a piece of a few tets (at most 8) that the marks would cut loose - a tet lying flat in
// the crease between two sweep triangles, marked on every face - keeps one mark closed,
// preferably one towards a large piece: it is an artefact of the discretisation, not tissue
// the blade severed.
#pragma once

#include "cutting/triangle_cut.hpp"

#include <set>

namespace stc {

// region_tets: the tets the cut touched (marked faces elsewhere are left alone). new_faces
// loses the faces that had to be dropped. Duplicates are appended to result.new_nodes.
void separate_along_cuts(TetMesh& mesh, CutState& state, const std::vector<int>& region_tets,
                         CutResult& result, std::set<FaceKey>& new_faces);

}  // namespace stc
