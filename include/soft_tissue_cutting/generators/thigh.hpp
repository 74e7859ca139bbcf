// The paper's experiment: a short portion of the upper leg with the thighbone removed.
#pragma once

#include "soft_tissue_cutting/scene/scene.hpp"

namespace stc {

// A thick tube along z, inner wall = bone surface. Structured in (r, theta, z) cells, each
// split into 6 tets with a consistent diagonal so neighbouring cells conform.
TetMesh make_thigh_mesh(const GeneratorParams& params);

// The thigh's operation region refined to the tet size cutting needs (TetGen); `tube` is
// make_thigh_mesh(p) with coordinates multiplied by `scale`. all/none regions: unchanged.
TetMesh refine_thigh_operation_region(const TetMesh& tube, const GeneratorParams& p,
                                      const OperationRegion& region, double scale = 1.0);

// Structured box [0, size] split into cells, 6 tets per cell.
TetMesh make_box_mesh(const GeneratorParams& params);

// The built-in `thigh` scene: the mesh, bone nodes fixed, an operation region on the outer
// wall, three loaded surface nodes in it.
Scene make_thigh_scene(double resolution = 1.0);

}  // namespace stc
