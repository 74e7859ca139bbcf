#include "soft_tissue_cutting/assembly/global_assembly.hpp"

namespace stc {

void add_element_triplets(const TetMesh& mesh, const ElementStiffnessCache& elements,
                          const std::vector<int>& tets, const std::vector<int>& row_of,
                          const std::vector<int>& col_of, std::vector<Triplet>& out) {
  for (int t : tets) {
    const Tet& e = mesh.tets[static_cast<size_t>(t)];
    const Mat12& k = elements[t];
    for (int a = 0; a < 12; ++a) {
      const int r = row_of[static_cast<size_t>(3 * e[a / 3] + a % 3)];
      if (r < 0) continue;
      for (int b = 0; b < 12; ++b) {
        const int c = col_of[static_cast<size_t>(3 * e[b / 3] + b % 3)];
        if (c >= 0) out.emplace_back(r, c, k(a, b));
      }
    }
  }
}

SparseMatrix assemble_stiffness(const TetMesh& mesh, const ElementStiffnessCache& elements,
                                const std::vector<int>& tets, const DofMap& map) {
  return assemble_block(mesh, elements, tets, map, map);
}

SparseMatrix assemble_block(const TetMesh& mesh, const ElementStiffnessCache& elements,
                            const std::vector<int>& tets, const DofMap& map_rows,
                            const DofMap& map_cols) {
  std::vector<Triplet> triplets;
  triplets.reserve(tets.size() * 144);
  add_element_triplets(mesh, elements, tets, map_rows.row_of, map_cols.row_of, triplets);
  SparseMatrix k(map_rows.rows(), map_cols.rows());
  k.setFromTriplets(triplets.begin(), triplets.end());  // duplicates are summed
  return k;
}

DofMap make_dof_map(int num_nodes, const std::vector<int>& nodes,
                    const std::vector<std::uint8_t>& fixed_node) {
  DofMap map;
  map.row_of.assign(static_cast<size_t>(3 * num_nodes), -1);
  for (int n : nodes) {
    if (!fixed_node.empty() && fixed_node[static_cast<size_t>(n)]) continue;
    for (int c = 0; c < 3; ++c) {
      map.row_of[static_cast<size_t>(3 * n + c)] = map.rows();
      map.global_of.push_back(3 * n + c);
    }
  }
  return map;
}

Vector gather(const Vector& global, const DofMap& map) {
  Vector local(map.rows());
  for (int i = 0; i < map.rows(); ++i) local[i] = global[map.global_of[static_cast<size_t>(i)]];
  return local;
}

void scatter(const Vector& local, const DofMap& map, Vector& global) {
  for (int i = 0; i < map.rows(); ++i) global[map.global_of[static_cast<size_t>(i)]] = local[i];
}

}  // namespace stc
