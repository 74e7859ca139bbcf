#include "soft_tissue_cutting/simulation/operation_surface.hpp"

#include <algorithm>
#include <atomic>

namespace stc {
namespace {

std::array<int, 3> key(const Tri& t) {
  std::array<int, 3> k = {t[0], t[1], t[2]};
  std::sort(k.begin(), k.end());
  return k;
}

}  // namespace

TetMesh tet_subset(const TetMesh& mesh, const std::vector<int>& tets) {
  TetMesh sub;
  sub.nodes = mesh.nodes;  // free_pieces reads anchored nodes' positions
  sub.tets.reserve(tets.size());
  for (int t : tets) sub.tets.push_back(mesh.tets[static_cast<size_t>(t)]);
  if (!mesh.cut_faces.empty()) {
    sub.cut_faces.reserve(tets.size());
    for (int t : tets) sub.cut_faces.push_back(mesh.cut_faces[static_cast<size_t>(t)]);
  }
  return sub;
}

void OperationSurface::init(const TetMesh& mesh, const std::vector<std::uint8_t>& operation_tet) {
  const BoundarySurface full = extract_boundary_surface(mesh);
  condensed_.clear();
  std::vector<std::array<int, 3>> part1_on_boundary;
  for (const BoundaryTriangle& t : full.triangles) {
    if (operation_tet[static_cast<size_t>(t.tet)])
      part1_on_boundary.push_back(key(t.nodes));
    else
      condensed_.push_back(t);
  }
  std::vector<int> part1;
  for (int t = 0; t < mesh.num_tets(); ++t)
    if (operation_tet[static_cast<size_t>(t)]) part1.push_back(t);
  part1_.build(mesh, part1);
  const BoundarySurface own = part1_.boundary(mesh);
  // Faces on part 1's own boundary that are not on the tissue's: shared with part 2.
  std::sort(part1_on_boundary.begin(), part1_on_boundary.end());
  shared_.clear();
  for (const BoundaryTriangle& t : own.triangles)
    if (!std::binary_search(part1_on_boundary.begin(), part1_on_boundary.end(), key(t.nodes)))
      shared_.push_back(key(t.nodes));
  std::sort(shared_.begin(), shared_.end());
  condensed_non_manifold_ = std::max(0, full.non_manifold_faces - own.non_manifold_faces);
  static std::atomic<long> extractions{0};  // a moved region's surface is made on its worker
  extraction_ = ++extractions;
}

void OperationSurface::update(const TetMesh& mesh, const std::vector<int>& changed) {
  part1_.update(mesh, changed);
}

BoundarySurface OperationSurface::current(const TetMesh& mesh) const {
  BoundarySurface s = operation_part(mesh);
  s.triangles.insert(s.triangles.begin(), condensed_.begin(), condensed_.end());
  return s;
}

BoundarySurface OperationSurface::operation_part(const TetMesh& mesh) const {
  BoundarySurface s;
  const BoundarySurface own = part1_.boundary(mesh);
  s.triangles.reserve(own.triangles.size());
  for (const BoundaryTriangle& t : own.triangles)
    if (!std::binary_search(shared_.begin(), shared_.end(), key(t.nodes))) s.triangles.push_back(t);
  s.non_manifold_faces = condensed_non_manifold_ + own.non_manifold_faces;
  return s;
}

}  // namespace stc
