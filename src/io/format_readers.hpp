// The per-format readers behind read_mesh (private to src/io). Each returns the raw mesh in
// file order with the line of every node/tet; read_mesh validates it afterwards.
#pragma once

#include "soft_tissue_cutting/io/mesh_reader.hpp"

#include <string>
#include <vector>

namespace stc::io {

struct RawMesh {
  TetMesh mesh;
  MeshLines lines;
};

// A closed triangle surface (OBJ/STL/OFF), before tetrahedralization.
struct Surface {
  std::vector<Vec3> vertices;
  std::vector<Tri> triangles;
  std::vector<int> triangle_line;
};

RawMesh read_gmsh(const std::string& path, const std::string& data);
RawMesh read_tetgen(const std::string& node_path);
RawMesh read_vtk_legacy(const std::string& path, const std::string& data);
RawMesh read_vtu(const std::string& path, const std::string& data);

Surface read_obj(const std::string& path, const std::string& data);
Surface read_stl(const std::string& path, const std::string& data);
Surface read_off(const std::string& path, const std::string& data);
// Refuses open or non-manifold surfaces, then runs TetGen with `switches`.
RawMesh tetrahedralize_surface(const std::string& path, const Surface& surface,
                               const std::string& switches);

}  // namespace stc::io
