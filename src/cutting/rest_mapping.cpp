#include "soft_tissue_cutting/cutting/rest_mapping.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stc {

void DeformedToRest::build(const TetMesh& mesh, const Eigen::VectorXd& displacement,
                           const std::vector<std::uint8_t>& include) {
  std::vector<int> tets;
  for (size_t t = 0; t < mesh.tets.size(); ++t)
    if (include.empty() || include[t]) tets.push_back(static_cast<int>(t));
  const Vec3 everywhere = Vec3::Constant(std::numeric_limits<double>::infinity());
  build(mesh, displacement, tets, -everywhere, everywhere);
}

void DeformedToRest::build(const TetMesh& mesh, const Eigen::VectorXd& displacement,
                           const std::vector<int>& tets, const Vec3& lo, const Vec3& hi) {
  // Only the kept tets and their nodes are copied, renumbered: a cut step's map holds a few
  // hundred tets of a mesh of tens of thousands of nodes, and is rebuilt at every cut.
  const auto deformed = [&](int v) -> Vec3 {
    return mesh.nodes[static_cast<size_t>(v)] + displacement.segment<3>(3 * v);
  };
  std::vector<Tet> kept;
  for (int t : tets) {
    const Tet& k = mesh.tets[static_cast<size_t>(t)];
    const Vec3 x0 = deformed(k[0]), x1 = deformed(k[1]), x2 = deformed(k[2]), x3 = deformed(k[3]);
    const Vec3 t_lo = x0.cwiseMin(x1).cwiseMin(x2).cwiseMin(x3);
    const Vec3 t_hi = x0.cwiseMax(x1).cwiseMax(x2).cwiseMax(x3);
    if ((t_lo.array() <= hi.array()).all() && (t_hi.array() >= lo.array()).all()) kept.push_back(k);
  }
  std::vector<int> used;
  used.reserve(4 * kept.size());
  for (const Tet& k : kept) used.insert(used.end(), k.begin(), k.end());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  mesh_.nodes.resize(used.size());
  std::vector<Vec3> x(used.size());
  for (size_t i = 0; i < used.size(); ++i) {
    mesh_.nodes[i] = mesh.nodes[static_cast<size_t>(used[i])];
    x[i] = deformed(used[i]);
  }
  mesh_.tets = std::move(kept);
  for (Tet& k : mesh_.tets)
    for (int& v : k)
      v = static_cast<int>(std::lower_bound(used.begin(), used.end(), v) - used.begin());
  locator_.build(mesh_, std::move(x));
}

namespace {
Vec3 rest_point(const TetMesh& mesh, int tet, const std::array<double, 4>& w) {
  Vec3 r = Vec3::Zero();
  for (int k = 0; k < 4; ++k) r += w[k] * mesh.nodes[mesh.tets[tet][k]];
  return r;
}
}  // namespace

std::optional<Vec3> DeformedToRest::map(const Vec3& x) const {
  const auto hit = locator_.locate(x, 1e-9);
  if (!hit) return std::nullopt;
  return rest_point(mesh_, hit->tet, hit->barycentric);
}

std::optional<std::vector<Vec3>> DeformedToRest::map_edge(const Vec3& tip, const Vec3& heel,
                                                          const std::vector<double>& s) const {
  const size_t n = s.size();
  std::vector<int> tet(n, -1);
  std::vector<Vec3> out(n);
  std::vector<Vec3> x(n);
  for (size_t i = 0; i < n; ++i) {
    x[i] = tip + s[i] * (heel - tip);
    if (const auto hit = locator_.locate(x[i], 1e-9)) {
      tet[i] = hit->tet;
      out[i] = rest_point(mesh_, hit->tet, hit->barycentric);
    }
  }
  if (std::all_of(tet.begin(), tet.end(), [](int t) { return t < 0; })) return std::nullopt;
  const std::vector<Vec3>& deformed = locator_.positions();
  for (size_t i = 0; i < n; ++i) {
    if (tet[i] >= 0) continue;
    size_t nearest = n;
    for (size_t j = 0; j < n; ++j)
      if (tet[j] >= 0 && (nearest == n || std::abs(s[j] - s[i]) < std::abs(s[nearest] - s[i])))
        nearest = j;
    const Tet& k = mesh_.tets[tet[nearest]];
    const auto w =
        barycentric(deformed[k[0]], deformed[k[1]], deformed[k[2]], deformed[k[3]], x[i]);
    out[i] = rest_point(mesh_, tet[nearest], w);
  }
  return out;
}

std::vector<int> simplify_polylines(const std::vector<Vec3>& a, const std::vector<Vec3>& b,
                                    double tolerance) {
  const int n = static_cast<int>(a.size());
  std::vector<char> keep(n, 0);
  if (n == 0) return {};
  keep[0] = keep[n - 1] = 1;
  std::vector<std::pair<int, int>> stack = {{0, n - 1}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    int worst = -1;
    double worst_d = tolerance;
    for (int k = i + 1; k < j; ++k) {
      const double t = static_cast<double>(k - i) / (j - i);  // samples are evenly spaced
      const double d = std::max((a[k] - (a[i] + t * (a[j] - a[i]))).norm(),
                                (b[k] - (b[i] + t * (b[j] - b[i]))).norm());
      if (d > worst_d) worst_d = d, worst = k;
    }
    if (worst < 0) continue;
    keep[worst] = 1;
    stack.push_back({i, worst});
    stack.push_back({worst, j});
  }
  std::vector<int> kept;
  for (int k = 0; k < n; ++k)
    if (keep[k]) kept.push_back(k);
  return kept;
}

}  // namespace stc
