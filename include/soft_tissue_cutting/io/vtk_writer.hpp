// Writing a mesh state as VTK legacy ASCII UNSTRUCTURED_GRID (docs/SCENE.md "Offline run", a
// contract).
#pragma once

#include "soft_tissue_cutting/io/mesh_error.hpp"
#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace stc {

// POINTS = rest positions (node i = mesh node i), CELLS = tets as stored (type 10),
// POINT_DATA `VECTORS displacement double` (3n entries, node-major), CELL_DATA
// `SCALARS region int` (1 = operation part, 0 = not). Numbers use %.17g so read_mesh gives
// the same doubles back. An empty `displacement` or `tet_region` is written as zeros; any
// other size mismatch, or a file that cannot be written, throws MeshError.
void write_vtk(const std::string& path, const TetMesh& mesh, const Eigen::VectorXd& displacement,
               const std::vector<std::uint8_t>& tet_region);

}  // namespace stc
