#include "soft_tissue_cutting/scene/scene.hpp"

#include <algorithm>

namespace stc {

std::vector<int> NodeSelector::select(const TetMesh& mesh) const {
  std::vector<int> out;
  switch (kind) {
    case Kind::kNodes:
      for (int n : nodes)
        if (n >= 0 && n < mesh.num_nodes()) out.push_back(n);
      break;
    case Kind::kBox:
      for (int i = 0; i < mesh.num_nodes(); ++i)
        if (box.contains(mesh.nodes[i])) out.push_back(i);
      break;
    case Kind::kSphere:
      for (int i = 0; i < mesh.num_nodes(); ++i)
        if (sphere.contains(mesh.nodes[i])) out.push_back(i);
      break;
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

bool OperationRegion::contains(const Vec3& centroid) const {
  switch (kind) {
    case Kind::kAll:
      return true;
    case Kind::kNone:
      return false;
    case Kind::kSphere:
      return sphere.contains(centroid);
    case Kind::kBox:
      return box.contains(centroid);
  }
  return false;
}

}  // namespace stc
