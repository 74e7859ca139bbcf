// Conforming edge bisection: insert a node on an edge and split every tet that uses it.
#pragma once

#include "cutting/cut_state.hpp"

namespace stc {

// Splits edge (a, b) at x_a + t (x_b - x_a), 0 < t < 1. Each tet using the edge is split in
// two by the plane through the new node m and its two other vertices: the child with b
// replaced by m keeps the tet's index (volume t V), the child with a replaced by m is
// appended (volume (1 - t) V). Replacing a vertex in place by a point of the edge keeps the
// orientation positive and the volume exact. Cut-face bits follow the half-faces; the new
// face between the children is never a cut. Returns m; the split tets' indices (kept and
// appended) are added to `changed`.
int bisect_edge(TetMesh& mesh, CutState& state, int a, int b, double t, std::vector<int>& changed);

}  // namespace stc
