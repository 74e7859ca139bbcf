#include "structured_tets.hpp"

#include <utility>

namespace stc::detail {

void add_kuhn_tets(int ni, int nj, int nk, const std::function<int(int, int, int)>& node_index,
                   TetMesh& mesh) {
  // The six monotone paths from corner (0,0,0) to (1,1,1), one tet each.
  static const int kPaths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                   {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int i = 0; i < ni; ++i)
    for (int j = 0; j < nj; ++j)
      for (int k = 0; k < nk; ++k)
        for (const auto& path : kPaths) {
          int c[3] = {i, j, k};
          Tet tet;
          tet[0] = node_index(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[path[s]];
            tet[s + 1] = node_index(c[0], c[1], c[2]);
          }
          if (tet_volume(TetMesh{mesh.nodes, {tet}, {}}, 0) < 0) std::swap(tet[2], tet[3]);
          mesh.tets.push_back(tet);
        }
}

}  // namespace stc::detail
