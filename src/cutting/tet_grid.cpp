#include "cutting/tet_grid.hpp"

#include <algorithm>
#include <cmath>

namespace stc {

void tet_bounds(const TetMesh& mesh, int tet, Vec3& lo, Vec3& hi) {
  lo = hi = mesh.nodes[mesh.tets[tet][0]];
  for (int k = 1; k < 4; ++k) {
    lo = lo.cwiseMin(mesh.nodes[mesh.tets[tet][k]]);
    hi = hi.cwiseMax(mesh.nodes[mesh.tets[tet][k]]);
  }
}

void TetGrid::build(const TetMesh& mesh, const std::vector<std::uint8_t>& include) {
  cells_.clear();
  boxes_.assign(mesh.tets.size(), Box{Vec3::Zero(), Vec3::Zero()});
  seen_.assign(mesh.tets.size(), 0);
  stamp_ = 0;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  double extent_sum = 0;
  int count = 0;
  for (int t = 0; t < mesh.num_tets(); ++t) {
    if (!include.empty() && !include[t]) continue;
    Vec3 a, b;
    tet_bounds(mesh, t, a, b);
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(b);
    extent_sum += (b - a).maxCoeff();
    ++count;
  }
  if (count == 0) {
    origin_ = Vec3::Zero();
    dims_ = {1, 1, 1};
    cells_.resize(1);
    return;
  }
  // Cells about one tet across: a query box meets O(1) cells per tet it overlaps. Capped so
  // a mesh with a few huge tets cannot ask for an absurd grid.
  cell_size_ = std::max(extent_sum / count, 1e-12);
  const Vec3 span = hi - lo;
  for (int d = 0; d < 3; ++d) {
    const double n = std::ceil(span[d] / cell_size_) + 1;
    dims_[d] = static_cast<int>(std::clamp(n, 1.0, 256.0));
  }
  origin_ = lo;
  cells_.resize(static_cast<size_t>(dims_[0]) * dims_[1] * dims_[2]);
  for (int t = 0; t < mesh.num_tets(); ++t)
    if (include.empty() || include[t]) insert(mesh, t);
}

std::array<int, 3> TetGrid::cell_of(const Vec3& p) const {
  std::array<int, 3> c;
  for (int d = 0; d < 3; ++d) {
    const double x = std::floor((p[d] - origin_[d]) / cell_size_);
    c[d] = static_cast<int>(std::clamp(x, 0.0, static_cast<double>(dims_[d] - 1)));
  }
  return c;
}

void TetGrid::refresh(const TetMesh& mesh, int tet) {
  if (boxes_.size() < mesh.tets.size())
    boxes_.resize(mesh.tets.size(), Box{Vec3::Zero(), Vec3::Zero()});
  Box& box = boxes_[static_cast<size_t>(tet)];
  tet_bounds(mesh, tet, box.lo, box.hi);
}

void TetGrid::insert(const TetMesh& mesh, int tet) {
  refresh(mesh, tet);
  const Box& box = boxes_[static_cast<size_t>(tet)];
  const auto a = cell_of(box.lo), b = cell_of(box.hi);
  for (int k = a[2]; k <= b[2]; ++k)
    for (int j = a[1]; j <= b[1]; ++j)
      for (int i = a[0]; i <= b[0]; ++i)
        cells_[(static_cast<size_t>(k) * dims_[1] + j) * dims_[0] + i].push_back(tet);
}

std::vector<int> TetGrid::query(const TetMesh& mesh, const Vec3& lo, const Vec3& hi) const {
  if (seen_.size() < mesh.tets.size()) seen_.resize(mesh.tets.size(), 0);
  if (++stamp_ == 0) {  // wrapped: forget old stamps
    std::fill(seen_.begin(), seen_.end(), 0);
    stamp_ = 1;
  }
  std::vector<int> found;
  first_overlapping(lo, hi, [&](int t, const Vec3&, const Vec3&) {
    if (seen_[t] != stamp_) found.push_back(t);  // a tet listed in several cells: once
    seen_[t] = stamp_;
    return false;
  });
  std::sort(found.begin(), found.end());
  return found;
}

bool TetGrid::any(const TetMesh&, const Vec3& lo, const Vec3& hi) const {
  return first_overlapping(lo, hi, [](int, const Vec3&, const Vec3&) { return true; });
}

void TetGrid::grow_by_overlapping(const TetMesh&, const Vec3& lo, const Vec3& hi, Vec3& ulo,
                                  Vec3& uhi) const {
  first_overlapping(lo, hi, [&](int, const Vec3& a, const Vec3& b) {
    ulo = ulo.cwiseMin(a);
    uhi = uhi.cwiseMax(b);
    return false;
  });
}

}  // namespace stc
