// Reading tetrahedral meshes (docs/SCENE.md "Meshes"): Gmsh, TetGen, VTK legacy, VTK XML, and
// closed surfaces tetrahedralized with the TetGen library.
#pragma once

#include "soft_tissue_cutting/io/mesh_error.hpp"
#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

#include <string>
#include <vector>

namespace stc {

struct MeshReadOptions {
  // TetGen switches for .obj/.stl/.off surfaces: p = piecewise linear complex, q1.4 = radius-
  // edge quality bound, Q = quiet. Must keep `p` (the input is a surface, not a point cloud).
  std::string tetgen_switches = "pq1.4Q";
};

// Reads `path`, dispatching on its extension (case-insensitive):
//   .msh          Gmsh 1 ($NOD/$ELM), 2.2 and 4.1, ASCII or binary; only tets (type 4) kept
//   .node         TetGen; the .ele beside it is read too (0- or 1-based as .node says)
//   .vtk          VTK legacy UNSTRUCTURED_GRID, ASCII or BINARY; only VTK_TETRA (10) kept
//   .vtu          VTK XML UnstructuredGrid, ascii DataArrays; only VTK_TETRA kept
//   .obj/.stl/.off  closed triangle surface, tetrahedralized with TetGen
// Node i of the result is the i-th node of the file (tags mapped in file order). The mesh is
// validated (see validate_tet_mesh); non-fatal findings (all tets flipped, unreferenced nodes)
// are appended to `warnings` when given. Any problem throws MeshError, never crashes.
TetMesh read_mesh(const std::string& path, const MeshReadOptions& options = {},
                  std::vector<std::string>* warnings = nullptr);

// Where each node/tet came from, for messages that name a line (0 = no line).
struct MeshLines {
  std::vector<int> node_line;
  std::vector<int> tet_line;
};

// The checks of docs/SCENE.md "Meshes" on a mesh from any source: finite coordinates, indices in
// range, four distinct nodes per tet, no zero-volume tet, one orientation (all negative: flipped
// with a warning; mixed: refused), no face shared by more than two tets or by two tets on the same
// side (via extract_boundary_surface), at least one tet. Unreferenced nodes are kept with a
// warning. `path` prefixes messages; `lines` (optional) adds line numbers.
void validate_tet_mesh(TetMesh& mesh, const std::string& path,
                       std::vector<std::string>* warnings = nullptr,
                       const MeshLines* lines = nullptr);

}  // namespace stc
