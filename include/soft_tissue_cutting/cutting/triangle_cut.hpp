// Inserting one planar cut triangle into the tet mesh (steps a-c of the cut): classify nodes
// against its plane (snapping the near ones), bisect the edges that cross the triangle, and
// mark the faces that now lie on it. Separation (separation.hpp) is a later, separate step.
#pragma once

#include "soft_tissue_cutting/cutting/cut_result.hpp"
#include "soft_tissue_cutting/cutting/cut_state.hpp"

#include <array>
#include <set>

namespace stc {

using FaceKey = std::array<int, 3>;  // sorted node triple

// Marks cut faces only between two cuttable tets. Newly marked faces are added to
// `new_faces`; new nodes, split counts and changed tets go to `result`. A degenerate
// triangle (no area) does nothing.
void insert_cut_triangle(TetMesh& mesh, CutState& state, const Vec3& a, const Vec3& b,
                         const Vec3& c, const CutOptions& options, CutResult& result,
                         std::set<FaceKey>& new_faces);

// The tet across local face `face` of `tet` and that tet's local index of the face, or
// {-1, -1} on the boundary.
std::pair<int, int> neighbour_across(const TetMesh& mesh, const CutState& state, int tet, int face);

}  // namespace stc
