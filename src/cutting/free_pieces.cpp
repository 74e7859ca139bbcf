#include "cutting/free_pieces.hpp"

#include <algorithm>
#include <numeric>

namespace stc {
namespace {

int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

std::vector<MeshPiece> mesh_pieces(const TetMesh& mesh) {
  // Union-find over nodes: the 4 nodes of a tet are one piece.
  std::vector<int> parent(mesh.nodes.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const Tet& tet : mesh.tets)
    for (int k = 1; k < 4; ++k) {
      const int a = find_root(parent, tet[0]), b = find_root(parent, tet[k]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  std::vector<int> piece_of_root(mesh.nodes.size(), -1);
  std::vector<MeshPiece> pieces;
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const int root = find_root(parent, mesh.tets[t][0]);
    if (piece_of_root[root] < 0) {
      piece_of_root[root] = static_cast<int>(pieces.size());
      pieces.emplace_back();
    }
    pieces[piece_of_root[root]].tets.push_back(t);
  }
  std::vector<char> used(mesh.nodes.size(), 0);
  for (const Tet& tet : mesh.tets)
    for (int v : tet) used[v] = 1;
  for (int v = 0; v < mesh.num_nodes(); ++v)
    if (used[v]) pieces[piece_of_root[find_root(parent, v)]].nodes.push_back(v);
  return pieces;
}

std::vector<MeshPiece> free_pieces(const TetMesh& mesh, const std::vector<std::uint8_t>& anchored) {
  std::vector<MeshPiece> free;
  for (MeshPiece& piece : mesh_pieces(mesh)) {
    bool held = false;
    for (int v : piece.nodes) held |= v < static_cast<int>(anchored.size()) && anchored[v];
    if (!held) free.push_back(std::move(piece));
  }
  return free;
}

}  // namespace stc
