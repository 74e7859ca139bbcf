// Local refinement of a tet mesh with TetGen's library: the operation part, where the scalpel
// cuts, needs interior nodes (only they can be duplicated by a cut; the interface to the
// condensed part never is), while the condensed part can stay coarse.
#pragma once

#include "soft_tissue_cutting/scene/scene.hpp"

namespace stc {

// Refines the tets whose centroid lies in `region` until none is larger than `max_volume`
// (TetGen -r -a with per-tet volume limits), with quality bounds (radius-edge ratio 1.5,
// dihedral angles >= 18 deg) and mesh optimization. Deterministic. The input's nodes keep
// their indices; TetGen's new nodes follow. Throws std::runtime_error if TetGen fails.
TetMesh refine_region(const TetMesh& mesh, const OperationRegion& region, double max_volume);

}  // namespace stc
