#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

namespace stc {

double signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

double tet_volume(const TetMesh& mesh, int tet) {
  const Tet& t = mesh.tets[tet];
  return signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
}

double total_volume(const TetMesh& mesh) {
  // Kahan-free pairwise would be overkill: volumes are summed in tet order, and the 1e-9
  // volume invariant (docs/SCENE.md "Cut invariants") is far above double round-off for meshes of
  // this size.
  double v = 0;
  for (int t = 0; t < mesh.num_tets(); ++t) v += tet_volume(mesh, t);
  return v;
}

}  // namespace stc
