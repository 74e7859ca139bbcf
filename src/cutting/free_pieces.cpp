#include "cutting/free_pieces.hpp"

#include "soft_tissue_cutting/mesh/boundary_surface.hpp"

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

std::vector<MeshPiece> face_connected_pieces(const TetMesh& mesh) {
  // Union-find over tets: the users of one face (neighbours in faces_by_key) are one piece.
  std::vector<int> parent(mesh.tets.size());
  std::iota(parent.begin(), parent.end(), 0);
  const std::vector<KeyedFace> faces = faces_by_key(mesh);
  for (size_t i = 1; i < faces.size(); ++i) {
    if (faces[i].key != faces[i - 1].key) continue;
    const int a = find_root(parent, faces[i].tet), b = find_root(parent, faces[i - 1].tet);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  std::vector<int> piece_of_root(mesh.tets.size(), -1);
  std::vector<MeshPiece> pieces;
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const int root = find_root(parent, t);
    if (piece_of_root[root] < 0) {
      piece_of_root[root] = static_cast<int>(pieces.size());
      pieces.emplace_back();
    }
    pieces[piece_of_root[root]].tets.push_back(t);
  }
  for (MeshPiece& piece : pieces) {
    for (int t : piece.tets)
      for (int v : mesh.tets[t]) piece.nodes.push_back(v);
    std::sort(piece.nodes.begin(), piece.nodes.end());
    piece.nodes.erase(std::unique(piece.nodes.begin(), piece.nodes.end()), piece.nodes.end());
  }
  return pieces;
}

std::vector<MeshPiece> free_pieces(const TetMesh& mesh, const std::vector<std::uint8_t>& anchored) {
  // Pieces by shared FACES: a piece that hangs on the rest by a node or an edge only (a
  // hinge: it can rotate about it) has a singular stiffness, so it counts as its own piece.
  return free_pieces(face_connected_pieces(mesh), mesh, anchored);
}

std::vector<MeshPiece> free_pieces(std::vector<MeshPiece> pieces, const TetMesh& mesh,
                                   const std::vector<std::uint8_t>& anchored) {
  std::vector<MeshPiece> free;
  for (MeshPiece& piece : pieces) {
    // Held in place only by three anchored nodes that are not on one line (one or two
    // would leave it free to rotate).
    std::vector<Vec3> held;
    for (int v : piece.nodes)
      if (v < static_cast<int>(anchored.size()) && anchored[v]) held.push_back(mesh.nodes[v]);
    bool rigid = false;
    if (held.size() >= 3) {
      size_t far = 1;
      for (size_t i = 1; i < held.size(); ++i)
        if ((held[i] - held[0]).norm() > (held[far] - held[0]).norm()) far = i;
      const Vec3 axis = held[far] - held[0];
      double off = 0;
      for (const Vec3& x : held) off = std::max(off, axis.cross(x - held[0]).norm());
      rigid = off > 1e-6 * axis.squaredNorm();  // a triangle of non-negligible area
    }
    if (!rigid) free.push_back(std::move(piece));
  }
  return free;
}

const MeshPiece* smallest_piece_with_node(const std::vector<MeshPiece>& pieces, int node) {
  const MeshPiece* best = nullptr;
  for (const MeshPiece& piece : pieces)
    if (std::binary_search(piece.nodes.begin(), piece.nodes.end(), node) &&
        (!best || piece.tets.size() < best->tets.size()))
      best = &piece;
  return best;
}

}  // namespace stc
