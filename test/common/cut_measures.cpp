#include "common/cut_measures.hpp"

#include "soft_tissue_cutting/mesh/boundary_surface.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <utility>

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

TetShapes tet_shapes(const TetMesh& mesh, const std::vector<std::uint8_t>& selected,
                     double below_deg) {
  TetShapes out;
  for (int t = 0; t < mesh.num_tets(); ++t) {
    if (!selected.empty() && !selected[static_cast<size_t>(t)]) continue;
    const Tet& e = mesh.tets[static_cast<size_t>(t)];
    const double angle = smallest_dihedral_deg(mesh.nodes[e[0]], mesh.nodes[e[1]], mesh.nodes[e[2]],
                                               mesh.nodes[e[3]]);
    out.least = std::min(out.least, angle);
    out.thin += angle < below_deg;
  }
  return out;
}

int thin_tets(const TetMesh& mesh, double below_deg) {
  return tet_shapes(mesh, {}, below_deg).thin;
}

int sharp_wedges(const TetMesh& mesh, double below_deg) {
  std::map<std::pair<int, int>, double> angle;  // per edge (ascending node ids), in degrees
  for (const Tet& e : mesh.tets) {
    const std::array<double, 6> at =
        dihedral_angles_deg(mesh.nodes[e[0]], mesh.nodes[e[1]], mesh.nodes[e[2]], mesh.nodes[e[3]]);
    // Angle k is between faces f < g (face f opposite corner f), in the order (0,1), (0,2),
    // (0,3), (1,2), (1,3), (2,3): at the edge joining the two other corners.
    int k = 0;
    for (int f = 0; f < 4; ++f)
      for (int g = f + 1; g < 4; ++g, ++k) {
        int i = -1, j = -1;
        for (int c = 0; c < 4; ++c)
          if (c != f && c != g) (i < 0 ? i : j) = c;
        angle[{std::min(e[i], e[j]), std::max(e[i], e[j])}] += at[static_cast<size_t>(k)];
      }
  }
  int sharp = 0;
  for (const auto& [edge, sum] : angle) sharp += sum < below_deg;
  return sharp;
}

int closed_cut_faces(const TetMesh& mesh) {
  int sides = 0, open = 0;
  for (std::uint8_t bits : mesh.cut_faces) sides += __builtin_popcount(bits);
  for (const BoundaryTriangle& tri : extract_boundary_surface(mesh).triangles) open += tri.cut;
  return (sides - open) / 2;
}

SparseMatrix free_block(const HybridModel& model, const std::vector<std::uint8_t>& held_node) {
  const DofMap& dofs = model.hybrid_dofs();
  std::vector<int> keep(static_cast<size_t>(dofs.rows()), -1);
  int rows = 0;
  for (int r = 0; r < dofs.rows(); ++r) {
    const size_t node = static_cast<size_t>(dofs.global_of[static_cast<size_t>(r)] / 3);
    if (node >= held_node.size() || !held_node[node]) keep[static_cast<size_t>(r)] = rows++;
  }
  std::vector<Eigen::Triplet<double>> t;
  const SparseMatrix& a = model.hybrid_matrix();
  for (int r = 0; r < a.outerSize(); ++r)
    for (SparseMatrix::InnerIterator it(a, r); it; ++it)
      if (keep[r] >= 0 && keep[it.col()] >= 0) t.emplace_back(keep[r], keep[it.col()], it.value());
  SparseMatrix out(rows, rows);
  out.setFromTriplets(t.begin(), t.end());
  return out;
}

}  // namespace stc::test
