#include "common/cut_measures.hpp"

#include "soft_tissue_cutting/mesh/boundary_surface.hpp"

namespace stc::test {

double open_cut_area(const TetMesh& mesh) {
  double area = 0;
  for (const BoundaryTriangle& tri : extract_boundary_surface(mesh).triangles) {
    if (!tri.cut) continue;
    const Vec3& a = mesh.nodes[tri.nodes[0]];
    area += 0.5 * (mesh.nodes[tri.nodes[1]] - a).cross(mesh.nodes[tri.nodes[2]] - a).norm();
  }
  return area;
}

int closed_cut_faces(const TetMesh& mesh) {
  int sides = 0, open = 0;
  for (std::uint8_t bits : mesh.cut_faces) sides += __builtin_popcount(bits);
  for (const BoundaryTriangle& tri : extract_boundary_surface(mesh).triangles) open += tri.cut;
  return (sides - open) / 2;
}

}  // namespace stc::test
