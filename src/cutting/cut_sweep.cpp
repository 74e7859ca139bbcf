#include "soft_tissue_cutting/cutting/cut_sweep.hpp"

#include "soft_tissue_cutting/cutting/separation.hpp"
#include "soft_tissue_cutting/cutting/triangle_cut.hpp"

#include <algorithm>

namespace stc {
namespace {

long count_marked_face_sides(const TetMesh& mesh) {
  long sides = 0;
  for (std::uint8_t bits : mesh.cut_faces) sides += __builtin_popcount(bits);
  return sides;
}

}  // namespace

CutResult cut_triangles(TetMesh& mesh, CutState& state,
                        const std::vector<std::array<Vec3, 3>>& triangles,
                        const CutOptions& options) {
  CutResult result;
  std::set<FaceKey> new_faces;
  const long marked_before = count_marked_face_sides(mesh);
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const auto& tri : triangles) {
    insert_cut_triangle(mesh, state, tri[0], tri[1], tri[2], options, result, new_faces);
    for (const Vec3& p : tri) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  if (!triangles.empty()) {
    // Marked faces lie inside the triangles' box; their tets overlap it.
    const Vec3 pad = Vec3::Constant(1e-6 * (hi - lo).norm());
    std::vector<int> region;
    for (int t : state.grid.query(mesh, lo - pad, hi + pad))
      if (state.cuttable[t]) region.push_back(t);
    separate_along_cuts(mesh, state, region, result, new_faces);
  }
  std::sort(result.changed_tets.begin(), result.changed_tets.end());
  result.changed_tets.erase(std::unique(result.changed_tets.begin(), result.changed_tets.end()),
                            result.changed_tets.end());
  result.nodes_added = static_cast<int>(result.new_nodes.size());
  // Net new cut faces: each face is marked on both of its sides (open or closed), and a cut
  // face halved by a later split counts as one more.
  result.cut_faces_added = static_cast<int>((count_marked_face_sides(mesh) - marked_before) / 2);
  return result;
}

CutResult cut_sweep(TetMesh& mesh, CutState& state, const BladeEdge& from, const BladeEdge& to,
                    const CutOptions& options) {
  return cut_triangles(mesh, state,
                       {{from.tip, from.heel, to.heel}, {from.tip, to.heel, to.tip}}, options);
}

}  // namespace stc
