// Shared by the thigh and box generators: a structured grid of hexahedral cells split into
// six tets each (Kuhn/Freudenthal split along the cell's main diagonal). The split depends
// only on index-space orientation, so neighbouring cells, including across a periodic seam,
// share their face diagonals and the mesh is conforming.
#pragma once

#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

#include <functional>

namespace stc::detail {

// node_index(i, j, k) for grid corner (i, j, k); cells span [0, ni) x [0, nj) x [0, nk).
// Tets are made positively oriented in the mapped coordinates.
void add_kuhn_tets(int ni, int nj, int nk, const std::function<int(int, int, int)>& node_index,
                   TetMesh& mesh);

}  // namespace stc::detail
