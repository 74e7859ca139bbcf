#include "soft_tissue_cutting/assembly/loads.hpp"

namespace stc {

Vector point_loads(const Scene& scene) {
  Vector f = Vector::Zero(3 * scene.mesh.num_nodes());
  for (const Load& load : scene.loads) {
    const std::vector<int> nodes = load.where.select(scene.mesh);
    if (nodes.empty()) continue;
    const Vec3 per_node =
        load.total ? Vec3(load.force / static_cast<double>(nodes.size())) : load.force;
    for (int n : nodes) f.segment<3>(3 * n) += per_node;
  }
  return f;
}

Vector gravity_loads(const TetMesh& mesh, double density, const Vec3& gravity) {
  Vector f = Vector::Zero(3 * mesh.num_nodes());
  if (gravity.isZero(0.0)) return f;
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const Vec3 share = density * tet_volume(mesh, t) / 4.0 * gravity;
    for (int n : mesh.tets[static_cast<size_t>(t)]) f.segment<3>(3 * n) += share;
  }
  return f;
}

std::vector<std::uint8_t> fixed_node_mask(const Scene& scene) {
  std::vector<std::uint8_t> fixed(static_cast<size_t>(scene.mesh.num_nodes()), 0);
  for (const NodeSelector& s : scene.fixed)
    for (int n : s.select(scene.mesh)) fixed[static_cast<size_t>(n)] = 1;
  return fixed;
}

}  // namespace stc
