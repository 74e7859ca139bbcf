#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

#include <cstdio>

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

std::string mesh_hash(const TetMesh& mesh) {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  };
  for (const Vec3& x : mesh.nodes) mix(x.data(), 3 * sizeof(double));
  for (const Tet& t : mesh.tets) mix(t.data(), 4 * sizeof(int));
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

}  // namespace stc
