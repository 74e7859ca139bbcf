#include "soft_tissue_cutting/partition/follow_region.hpp"

namespace stc {

std::vector<std::uint8_t> follow_region_labels(const TetMesh& mesh, const Sphere& ball,
                                               const std::vector<int>& keep_nodes) {
  std::vector<std::uint8_t> keep(static_cast<size_t>(mesh.num_nodes()), 0);
  for (int n : keep_nodes)
    if (n >= 0 && n < mesh.num_nodes()) keep[static_cast<size_t>(n)] = 1;
  std::vector<std::uint8_t> label(static_cast<size_t>(mesh.num_tets()), 0);
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const Tet& e = mesh.tets[static_cast<size_t>(t)];
    const Vec3 centroid =
        0.25 * (mesh.nodes[e[0]] + mesh.nodes[e[1]] + mesh.nodes[e[2]] + mesh.nodes[e[3]]);
    bool op = ball.contains(centroid);
    for (int v : e) op = op || keep[static_cast<size_t>(v)];
    label[static_cast<size_t>(t)] = op ? 1 : 0;
  }
  return label;
}

}  // namespace stc
