#include "collision/tissue_samples.hpp"

#include <algorithm>
#include <cmath>

namespace stc {
namespace {

int intervals(double length, double spacing) {
  if (!(spacing > 0) || !(length > 0)) return 1;
  return std::max(1, static_cast<int>(std::ceil(length / spacing)));
}

}  // namespace

std::vector<Vec3> edge_samples(const BladeEdge& edge, double spacing) {
  const int n = intervals((edge.heel - edge.tip).norm(), spacing);
  std::vector<Vec3> out;
  out.reserve(static_cast<size_t>(n + 1));
  for (int k = 0; k <= n; ++k)
    out.push_back(edge.tip + (edge.heel - edge.tip) * (static_cast<double>(k) / n));
  return out;
}

std::vector<Vec3> sweep_samples(const BladeEdge& a, const BladeEdge& b, double spacing) {
  const double along = std::max((a.heel - a.tip).norm(), (b.heel - b.tip).norm());
  const double across = std::max((b.tip - a.tip).norm(), (b.heel - a.heel).norm());
  const int n = intervals(along, spacing), m = intervals(across, spacing);
  std::vector<Vec3> out;
  out.reserve(static_cast<size_t>((n + 1) * (m + 1)));
  for (int j = 0; j <= m; ++j) {
    const double t = static_cast<double>(j) / m;
    const Vec3 tip = (1 - t) * a.tip + t * b.tip, heel = (1 - t) * a.heel + t * b.heel;
    for (int k = 0; k <= n; ++k) out.push_back(tip + (heel - tip) * (static_cast<double>(k) / n));
  }
  return out;
}

int tet_containing(const TetMesh& mesh, const TetGrid& grid, const Vec3& p) {
  for (int t : grid.query(mesh, p, p)) {
    const Tet& k = mesh.tets[static_cast<size_t>(t)];
    const Vec3 &a = mesh.nodes[k[0]], &b = mesh.nodes[k[1]], &c = mesh.nodes[k[2]],
               &d = mesh.nodes[k[3]];
    const double eps = -1e-12 * std::abs(signed_volume(a, b, c, d));
    if (signed_volume(p, b, c, d) >= eps && signed_volume(a, p, c, d) >= eps &&
        signed_volume(a, b, p, d) >= eps && signed_volume(a, b, c, p) >= eps)
      return t;
  }
  return -1;
}

std::vector<int> tets_near(const TetMesh& mesh, const TetGrid& grid, const Vec3& p, double reach) {
  const Vec3 r = Vec3::Constant(reach);
  return grid.query(mesh, p - r, p + r);
}

bool any_tet_near(const TetMesh& mesh, const TetGrid& grid, const Vec3& p, double reach) {
  const Vec3 r = Vec3::Constant(reach);
  return grid.any(mesh, p - r, p + r);
}

}  // namespace stc
