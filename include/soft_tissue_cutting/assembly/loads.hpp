// External loads and supports of a scene as global per-node data (docs/DESIGN.md section 2).
#pragma once

#include "soft_tissue_cutting/scene/scene.hpp"
#include "soft_tissue_cutting/solve/linear_solver.hpp"  // Vector

#include <cstdint>
#include <vector>

namespace stc {

// Concentrated nodal forces (3n): `force` acts on every selected node, `total_force` is split
// evenly over the selected nodes (docs/SCENE.md "Scene file"). Selectors are evaluated on
// scene.mesh.
Vector point_loads(const Scene& scene);

// Consistent body force of gravity for linear tets: each tet gives rho g V / 4 to each of its
// four nodes (3n).
Vector gravity_loads(const TetMesh& mesh, double density, const Vec3& gravity);

// 1 for nodes held at zero displacement by a `fixed` selector.
std::vector<std::uint8_t> fixed_node_mask(const Scene& scene);

}  // namespace stc
