#include "soft_tissue_cutting/assembly/full_model.hpp"

#include "soft_tissue_cutting/assembly/loads.hpp"

#include <numeric>

namespace stc {

FullModel assemble_full_model(const TetMesh& mesh, const ElementStiffnessCache& elements,
                              const Vector& loads, const std::vector<std::uint8_t>& fixed_node) {
  std::vector<std::uint8_t> used(static_cast<size_t>(mesh.num_nodes()), 0);
  for (const Tet& t : mesh.tets)
    for (int n : t) used[static_cast<size_t>(n)] = 1;
  std::vector<int> nodes;
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (used[static_cast<size_t>(n)]) nodes.push_back(n);
  std::vector<int> all_tets(static_cast<size_t>(mesh.num_tets()));
  std::iota(all_tets.begin(), all_tets.end(), 0);
  FullModel m;
  m.dofs = make_dof_map(mesh.num_nodes(), nodes, fixed_node);
  m.K = assemble_stiffness(mesh, elements, all_tets, m.dofs);
  m.f = gather(loads, m.dofs);
  return m;
}

FullModel assemble_full_model(const Scene& scene) {
  const ElementStiffnessCache elements(scene.mesh, scene.material);
  const Vector f =
      point_loads(scene) + gravity_loads(scene.mesh, scene.material.density, scene.gravity);
  return assemble_full_model(scene.mesh, elements, f, fixed_node_mask(scene));
}

}  // namespace stc
