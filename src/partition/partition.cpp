#include "soft_tissue_cutting/partition/partition.hpp"

#include "soft_tissue_cutting/mesh/boundary_surface.hpp"

namespace stc {

Partition partition_mesh(const TetMesh& mesh, const OperationRegion& region) {
  std::vector<std::uint8_t> operation_tet(static_cast<size_t>(mesh.num_tets()), 0);
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const Tet& e = mesh.tets[static_cast<size_t>(t)];
    const Vec3 centroid =
        0.25 * (mesh.nodes[e[0]] + mesh.nodes[e[1]] + mesh.nodes[e[2]] + mesh.nodes[e[3]]);
    operation_tet[static_cast<size_t>(t)] = region.contains(centroid) ? 1 : 0;
  }
  return partition_from_labels(mesh, std::move(operation_tet));
}

Partition partition_from_labels(const TetMesh& mesh, std::vector<std::uint8_t> operation_tet) {
  Partition p;
  p.operation_tet = std::move(operation_tet);
  // Bit 1: used by a part-1 tet, bit 2: used by a part-2 tet.
  std::vector<std::uint8_t> used(static_cast<size_t>(mesh.num_nodes()), 0);
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const bool op = p.operation_tet[static_cast<size_t>(t)] != 0;
    (op ? p.operation_tets : p.condensed_tets).push_back(t);
    for (int n : mesh.tets[static_cast<size_t>(t)]) used[static_cast<size_t>(n)] |= op ? 1 : 2;
  }
  std::vector<std::uint8_t> on_boundary(static_cast<size_t>(mesh.num_nodes()), 0);
  for (int n : boundary_nodes(extract_boundary_surface(mesh)))
    on_boundary[static_cast<size_t>(n)] = 1;
  p.node_set.assign(static_cast<size_t>(mesh.num_nodes()), NodeSet::kUnused);
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    switch (used[static_cast<size_t>(n)]) {
      case 1:
        p.node_set[n] = NodeSet::kOperation;
        p.operation.push_back(n);
        break;
      case 3:
        p.node_set[n] = NodeSet::kInterface;
        p.interface.push_back(n);
        break;
      case 2:
        if (on_boundary[static_cast<size_t>(n)]) {
          p.node_set[n] = NodeSet::kSurface;
          p.surface.push_back(n);
        } else {
          p.node_set[n] = NodeSet::kInterior;
          p.interior.push_back(n);
        }
        break;
      default:
        break;
    }
  }
  return p;
}

bool update_partition_for_operation_change(const TetMesh& mesh,
                                           const std::vector<int>& changed_tets, Partition& p) {
  const size_t old_tets = p.operation_tet.size();
  for (int t : changed_tets)
    if (t >= 0 && static_cast<size_t>(t) < old_tets && !p.operation_tet[static_cast<size_t>(t)])
      return false;  // a part-2 tet was changed
  // Nodes of part 2 (I, S, Q) keep their sets: part 2 did not change. Which nodes part 1 uses
  // now (its tets and the appended ones) decides O, and whether every interface node is still
  // shared: checked before p changes, so a refused change leaves p as it was (the caller
  // updates its partition in place: copying the whole-mesh lists cost a cut ~0.2 ms at organ
  // scale).
  std::vector<std::uint8_t> used(static_cast<size_t>(mesh.num_nodes()), 0);
  const auto use = [&](int t) {
    for (int n : mesh.tets[static_cast<size_t>(t)]) used[static_cast<size_t>(n)] = 1;
  };
  for (int t : p.operation_tets) use(t);
  for (int t = static_cast<int>(old_tets); t < mesh.num_tets(); ++t) use(t);
  for (int n : p.interface)
    if (!used[static_cast<size_t>(n)]) return false;
  for (size_t n = 0; n < p.node_set.size() && n < used.size(); ++n)
    if (used[n] && (p.node_set[n] == NodeSet::kSurface || p.node_set[n] == NodeSet::kInterior))
      return false;
  p.operation_tet.resize(static_cast<size_t>(mesh.num_tets()), 1);
  for (int t = static_cast<int>(old_tets); t < mesh.num_tets(); ++t) p.operation_tets.push_back(t);
  p.node_set.resize(static_cast<size_t>(mesh.num_nodes()), NodeSet::kUnused);
  p.operation.clear();
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    NodeSet& set = p.node_set[static_cast<size_t>(n)];
    if (set == NodeSet::kInterface) continue;
    if (used[static_cast<size_t>(n)]) {
      set = NodeSet::kOperation;
      p.operation.push_back(n);
    } else if (set == NodeSet::kOperation) {
      set = NodeSet::kUnused;  // every tet of it was replaced (its copies took over)
    }
  }
  return true;
}

}  // namespace stc
