// The partition of a `follow` operation region (docs/DESIGN.md, moving operation region):
// which tets form part 1 when the ball around the blade sits at a given place.
#pragma once

#include "soft_tissue_cutting/scene/scene.hpp"

#include <cstdint>
#include <vector>

namespace stc {

// Per tet, 1 = part 1: tets whose rest centroid lies in `ball`, plus every tet that uses one
// of `keep_nodes` (nodes that must stay operation or interface nodes: the ones the blade
// holds, held free pieces). Works on a cut mesh: cut tets outside the ball are condensed.
std::vector<std::uint8_t> follow_region_labels(const TetMesh& mesh, const Sphere& ball,
                                               const std::vector<int>& keep_nodes);

}  // namespace stc
