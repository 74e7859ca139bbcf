// Where the blade is in the tissue's REST coordinates (docs/DESIGN.md (cutting)): the mesh is
// cut in rest coordinates, but the blade moves through the deformed tissue. A point of the
// blade edge inside the deformed operation part is carried back through the deformed tet that
// contains it (barycentric coordinates, the inverse of the linear elements' own map); a point
// outside the tissue is carried by the affine map of the tet of the nearest edge point that
// is inside, so the part of the edge above the surface stays above it. The edge becomes a
// polyline in rest coordinates, kept only as fine as the deformation bends it.
#pragma once

#include "soft_tissue_cutting/collision/blade.hpp"
#include "soft_tissue_cutting/collision/tet_locator.hpp"

#include <optional>
#include <vector>

namespace stc {

class DeformedToRest {
 public:
  DeformedToRest() = default;
  DeformedToRest(const DeformedToRest&) = delete;  // the locator points at mesh_
  DeformedToRest& operator=(const DeformedToRest&) = delete;
  // displacement: 3 per node (x, y, z); include: per tet, nonzero = the tets whose displacement is
  // current (the operation part; empty = all). The rest nodes and tets are copied, so the map
  // stays valid while the mesh is cut: a ~cut path is carried through the deformation it was
  // requested in, however many steps run between its slices (simulation.hpp, PathCut).
  void build(const TetMesh& mesh, const Eigen::VectorXd& displacement,
             const std::vector<std::uint8_t>& include = {});
  // The same over `tets` (indices into mesh.tets, e.g. the operation part's list), keeping
  // only those whose deformed box overlaps [lo, hi]: enough for points in that box (a cut
  // step's edges: a few hundred tets instead of the operation part's thousands, and the
  // organ's 71k never scanned; rebuilt at every cut).
  void build(const TetMesh& mesh, const Eigen::VectorXd& displacement, const std::vector<int>& tets,
             const Vec3& lo, const Vec3& hi);
  // The rest position of deformed point x, or nothing when x is in no included tet.
  std::optional<Vec3> map(const Vec3& x) const;
  // The edge tip -> heel sampled at parameters s (ascending in [0, 1]) and carried to rest.
  // Nothing when no sample lies in the tissue (then the edge cuts nothing).
  std::optional<std::vector<Vec3>> map_edge(const Vec3& tip, const Vec3& heel,
                                            const std::vector<double>& s) const;

 private:
  TetMesh mesh_;        // the kept tets and their rest nodes, renumbered (no cut flags)
  TetLocator locator_;  // over deformed positions
};

// A swept band between two rest polylines sampled at the same parameters: the parameters to
// keep so that both polylines stay within `tolerance` of their chords between kept samples
// (Douglas-Peucker on both at once; first and last are always kept).
std::vector<int> simplify_polylines(const std::vector<Vec3>& a, const std::vector<Vec3>& b,
                                    double tolerance);

}  // namespace stc
