#include "soft_tissue_cutting/collision/tet_locator.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace stc {

std::array<double, 4> barycentric(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                                  const Vec3& p) {
  const double v = signed_volume(a, b, c, d);
  if (!(std::abs(v) > 0)) return {NAN, NAN, NAN, NAN};
  return {signed_volume(p, b, c, d) / v, signed_volume(a, p, c, d) / v,
          signed_volume(a, b, p, d) / v, signed_volume(a, b, c, p) / v};
}

void TetLocator::build(const TetMesh& mesh, std::vector<Vec3> positions,
                       const std::vector<std::uint8_t>& include) {
  mesh_ = &mesh;
  positions_ = std::move(positions);
  tets_.clear();
  std::vector<Box3> boxes;
  for (int t = 0; t < mesh.num_tets(); ++t) {
    if (!include.empty() && !include[static_cast<size_t>(t)]) continue;
    Box3 box;
    box.setEmpty();
    for (int v : mesh.tets[t]) box.extend(positions_[static_cast<size_t>(v)]);
    tets_.push_back(t);
    boxes.push_back(box);
  }
  tree_.build(std::move(boxes));
}

std::optional<TetLocation> TetLocator::locate(const Vec3& p, double tolerance) const {
  if (!mesh_ || !p.allFinite()) return std::nullopt;
  std::vector<int> candidates;
  tree_.overlapping(Box3(p, p), candidates);
  std::optional<TetLocation> best;
  double best_min = -tolerance;
  for (int k : candidates) {
    const Tet& t = mesh_->tets[static_cast<size_t>(tets_[static_cast<size_t>(k)])];
    const auto w =
        barycentric(positions_[t[0]], positions_[t[1]], positions_[t[2]], positions_[t[3]], p);
    const double smallest = std::min({w[0], w[1], w[2], w[3]});
    if (smallest >= best_min) {
      best_min = smallest;
      best = TetLocation{tets_[static_cast<size_t>(k)], w};
    }
  }
  return best;
}

}  // namespace stc
