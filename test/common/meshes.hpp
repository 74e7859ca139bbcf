// Small meshes shared by the unit tests.
#pragma once

#include "soft_tissue_cutting/generators/thigh.hpp"

namespace stc::test {

// A 4 cm cube in 1 cm cells (6 Kuhn tets each).
inline TetMesh cube_mesh() {
  GeneratorParams g;
  g.size = Vec3(0.04, 0.04, 0.04);
  g.cells = {4, 4, 4};
  return make_box_mesh(g);
}

}  // namespace stc::test
