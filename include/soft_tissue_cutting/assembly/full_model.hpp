// The general (uncondensed) model: K over every free DOF of the whole mesh. The reference the
// hybrid model must equal (docs/DESIGN.md section 4: "exact, not an approximation"), and the
// "general model" of the paper's Table 1.
#pragma once

#include "soft_tissue_cutting/assembly/global_assembly.hpp"
#include "soft_tissue_cutting/scene/scene.hpp"

namespace stc {

struct FullModel {
  DofMap dofs;     // every DOF of a tet-referenced, non-fixed node
  SparseMatrix K;  // K_ff
  Vector f;        // f_f (point loads + gravity)
};

// loads: global 3n vector; fixed_node: per node.
FullModel assemble_full_model(const TetMesh& mesh, const ElementStiffnessCache& elements,
                              const Vector& loads, const std::vector<std::uint8_t>& fixed_node);

// Convenience for a scene as given: elements, point loads + gravity, fixed nodes.
FullModel assemble_full_model(const Scene& scene);

}  // namespace stc
