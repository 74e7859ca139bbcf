#include "soft_tissue_cutting/mesh/face_adjacency.hpp"

#include <algorithm>
#include <numeric>

namespace stc {
namespace {

std::array<int, 3> sorted_face(const Tet& t, int f) {
  std::array<int, 3> k = {t[kTetFaces[f][0]], t[kTetFaces[f][1]], t[kTetFaces[f][2]]};
  std::sort(k.begin(), k.end());
  return k;
}

Tri oriented_face(const Tet& t, int f) {
  return {t[kTetFaces[f][0]], t[kTetFaces[f][1]], t[kTetFaces[f][2]]};
}

int find_root(std::vector<int>& parent, int x) {
  while (parent[static_cast<size_t>(x)] != x)
    x = parent[static_cast<size_t>(x)] =
        parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
  return x;
}

}  // namespace

void TetFaceAdjacency::build(const TetMesh& mesh, const std::vector<int>& tets) {
  faces_.clear();
  faces_.reserve(3 * tets.size());
  seen_.assign(mesh.tets.size(), Tet{-1, -1, -1, -1});
  member_.assign(mesh.tets.size(), 0);
  users_.assign(4 * mesh.tets.size(), 0);
  other_.assign(4 * mesh.tets.size(), -1);
  crowded_.clear();
  non_manifold_ = 0;
  update(mesh, tets);
}

void TetFaceAdjacency::add(int tet, const Tet& nodes, std::vector<Key>& touched) {
  for (int f = 0; f < 4; ++f) {
    const Key key = sorted_face(nodes, f);
    faces_[key].users.push_back(4 * tet + f);
    touched.push_back(key);
  }
}

void TetFaceAdjacency::remove(int tet, const Tet& nodes, std::vector<Key>& touched) {
  for (int f = 0; f < 4; ++f) {
    const Key key = sorted_face(nodes, f);
    const auto it = faces_.find(key);
    if (it == faces_.end()) continue;
    std::vector<int>& users = it->second.users;
    users.erase(std::remove(users.begin(), users.end(), 4 * tet + f), users.end());
    touched.push_back(key);
  }
}

// Recounts a face's users after a change: what each user's users_ entry says, whether the face
// is non-manifold (more than two users, or two winding it the same way: extract_boundary_surface's
// rule), and the running count of such faces.
void TetFaceAdjacency::refresh(const Key& key) {
  const auto it = faces_.find(key);
  if (it == faces_.end()) return;
  Face& face = it->second;
  non_manifold_ -= face.non_manifold;
  const size_t n = face.users.size();
  face.non_manifold = n > 2;
  if (n == 2) {
    const int a = face.users[0], b = face.users[1];
    const Tri ta = oriented_face(seen_[static_cast<size_t>(a / 4)], a % 4);
    const Tri tb = oriented_face(seen_[static_cast<size_t>(b / 4)], b % 4);
    bool same = false;  // tb a rotation of ta: both tets on the same side
    for (int r = 0; r < 3; ++r)
      same |= tb[0] == ta[r] && tb[1] == ta[(r + 1) % 3] && tb[2] == ta[(r + 2) % 3];
    face.non_manifold = same;
  }
  non_manifold_ += face.non_manifold;
  for (int u : face.users) {
    users_[static_cast<size_t>(u)] = static_cast<std::uint8_t>(std::min<size_t>(n, 255));
    other_[static_cast<size_t>(u)] = -1;
  }
  if (n == 2) {
    other_[static_cast<size_t>(face.users[0])] = face.users[1];
    other_[static_cast<size_t>(face.users[1])] = face.users[0];
  }
  const auto crowded = std::lower_bound(crowded_.begin(), crowded_.end(), key);
  const bool listed = crowded != crowded_.end() && *crowded == key;
  if (n > 2 && !listed) crowded_.insert(crowded, key);
  if (n <= 2 && listed) crowded_.erase(crowded);
  if (n == 0) faces_.erase(it);
}

void TetFaceAdjacency::update(const TetMesh& mesh, const std::vector<int>& changed) {
  const size_t tets = mesh.tets.size();
  if (seen_.size() < tets) {
    seen_.resize(tets, Tet{-1, -1, -1, -1});
    member_.resize(tets, 0);
    users_.resize(4 * tets, 0);
    other_.resize(4 * tets, -1);
  }
  std::vector<Key> touched;
  touched.reserve(8 * changed.size());
  for (int t : changed) {
    const size_t i = static_cast<size_t>(t);
    if (member_[i]) remove(t, seen_[i], touched);
    member_[i] = 1;
    seen_[i] = mesh.tets[i];
    add(t, seen_[i], touched);
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  for (const Key& key : touched) refresh(key);
}

BoundarySurface TetFaceAdjacency::boundary(const TetMesh& mesh) const {
  BoundarySurface s;
  s.non_manifold_faces = non_manifold_;
  for (size_t t = 0; t < member_.size(); ++t) {
    if (!member_[t]) continue;
    for (int f = 0; f < 4; ++f)
      if (users_[4 * t + f] == 1)
        s.triangles.push_back({oriented_face(seen_[t], f), static_cast<int>(t), f,
                               mesh.is_cut_face(static_cast<int>(t), f)});
  }
  return s;
}

std::vector<MeshPiece> TetFaceAdjacency::pieces(const TetMesh& mesh) const {
  // Union-find over member tets: every user of a face joins its first user (as
  // face_connected_pieces does).
  std::vector<int> parent(member_.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto join = [&parent](int x, int y) {
    const int a = find_root(parent, x), b = find_root(parent, y);
    if (a != b) parent[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
  };
  for (size_t slot = 0; slot < other_.size(); ++slot)
    if (other_[slot] >= 0 && member_[slot / 4]) join(static_cast<int>(slot / 4), other_[slot] / 4);
  for (const Key& key : crowded_) {
    const std::vector<int>& users = faces_.at(key).users;
    for (size_t k = 1; k < users.size(); ++k) join(users[0] / 4, users[k] / 4);
  }
  std::vector<int> piece_of_root(member_.size(), -1);
  std::vector<MeshPiece> pieces;
  for (size_t t = 0; t < member_.size(); ++t) {
    if (!member_[t]) continue;
    const int root = find_root(parent, static_cast<int>(t));
    if (piece_of_root[static_cast<size_t>(root)] < 0) {
      piece_of_root[static_cast<size_t>(root)] = static_cast<int>(pieces.size());
      pieces.emplace_back();
    }
    pieces[static_cast<size_t>(piece_of_root[static_cast<size_t>(root)])].tets.push_back(
        static_cast<int>(t));
  }
  // Each piece's nodes once (a node on a hinge is in each of its pieces), then sorted.
  std::vector<int> last_piece(mesh.nodes.size(), -1);
  for (size_t k = 0; k < pieces.size(); ++k) {
    MeshPiece& piece = pieces[k];
    for (int t : piece.tets)
      for (int v : mesh.tets[static_cast<size_t>(t)])
        if (last_piece[static_cast<size_t>(v)] != static_cast<int>(k)) {
          last_piece[static_cast<size_t>(v)] = static_cast<int>(k);
          piece.nodes.push_back(v);
        }
    std::sort(piece.nodes.begin(), piece.nodes.end());
  }
  return pieces;
}

}  // namespace stc
