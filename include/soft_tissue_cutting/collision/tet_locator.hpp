// Point location in a tet mesh at any node positions (rest, or rest + displacement): which
// tet contains a point and its barycentric coordinates there. The cutter uses it to carry the
// blade's swept surface from where the blade is (deformed tissue) back to rest coordinates,
// where the mesh is cut (docs/DESIGN.md (cutting)); tests use it to evaluate a displacement
// field at rest points.
#pragma once

#include "soft_tissue_cutting/collision/aabb_tree.hpp"
#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace stc {

struct TetLocation {
  int tet = -1;
  std::array<double, 4> barycentric = {0, 0, 0, 0};  // weights of the tet's nodes, sum 1
};

class TetLocator {
 public:
  // positions: per node (e.g. rest + u); include: per tet, nonzero = searched (empty = all).
  void build(const TetMesh& mesh, std::vector<Vec3> positions,
             const std::vector<std::uint8_t>& include = {});
  // The tet containing p (barycentric slack `tolerance`, relative), or nothing outside.
  // Of several (p on a shared face), the one with the largest smallest weight.
  std::optional<TetLocation> locate(const Vec3& p, double tolerance = 1e-9) const;
  const std::vector<Vec3>& positions() const { return positions_; }

 private:
  const TetMesh* mesh_ = nullptr;
  std::vector<Vec3> positions_;
  std::vector<int> tets_;  // primitive -> tet
  AabbTree tree_;
};

// Barycentric coordinates of p in tet (a, b, c, d); any sign (outside: some negative).
std::array<double, 4> barycentric(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                                  const Vec3& p);

}  // namespace stc
