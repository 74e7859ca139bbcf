// Phase 2 for a stroke's earlier triangles: a cut's splits create faces (and bring nodes onto
// the stroke) that may lie on any triangle the blade swept before in the same stroke, not only
// on this cut's own (triangle_cut.hpp).
#pragma once

#include "cutting/triangle_cut.hpp"

#include <array>
#include <set>
#include <vector>

namespace stc {

// Marks the faces that lie on one of `earlier` (the stroke's earlier triangles), by
// mark_face_on_triangle's tests, among the cuttable tets around the box [lo, hi] of this cut's
// own triangles (a face that only now appears belongs to a tet this cut touched; the tets
// overlapping that box, and every cuttable tet inside their box, are looked at). The result is
// that of mark_faces_on_triangle for each earlier triangle in turn on those of the tets whose
// boxes overlap it, bit for bit; what does not depend on the triangle is found once, and only
// faces whose corners may be on it and that pass necessary forms of its inside, plane and
// facing tests (docs/DESIGN.md section 8, eq. (19b)) are tested in full.
// The cuttable tets around a cut whose own triangles lie in the box [lo, hi]: those overlapping
// it and every cuttable tet inside their box (one grid query for all), ascending. lo and hi
// become that box.
std::vector<int> tets_around_cut(const TetMesh& mesh, const CutState& state, Vec3& lo, Vec3& hi);

void mark_faces_on_earlier_triangles(TetMesh& mesh, const CutState& state,
                                     const std::vector<std::array<Vec3, 3>>& earlier,
                                     const Vec3& lo, const Vec3& hi, const CutOptions& options,
                                     StrokeSurface& surface, double skin_slack, NodeScales& scales,
                                     CutResult& result, std::set<FaceKey>& new_faces);

}  // namespace stc
