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
  tracking_ = false;
  changed_since_.clear();
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
  if (!tracking_) return;
  changed_since_.insert(changed_since_.end(), changed.begin(), changed.end());
  for (const Key& key : touched)
    if (const auto it = faces_.find(key); it != faces_.end())
      for (int u : it->second.users) changed_since_.push_back(u / 4);
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

std::vector<std::pair<int, int>> TetFaceAdjacency::crowded_pairs() const {
  std::vector<std::pair<int, int>> pairs;  // (tet, tet across a crowded face)
  for (const Key& key : crowded_) {
    const std::vector<int>& users = faces_.at(key).users;
    for (int a : users)
      for (int b : users)
        if (a / 4 != b / 4) pairs.emplace_back(a / 4, b / 4);
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

template <typename Visit>
void TetFaceAdjacency::for_each_neighbour(int t,
                                          const std::vector<std::pair<int, int>>& crowded_pairs,
                                          Visit&& visit) const {
  for (int f = 0; f < 4; ++f) {
    const int across = other_[4 * static_cast<size_t>(t) + static_cast<size_t>(f)];
    if (across >= 0 && member_[static_cast<size_t>(across / 4)]) visit(across / 4);
  }
  if (crowded_pairs.empty()) return;
  for (auto it =
           std::lower_bound(crowded_pairs.begin(), crowded_pairs.end(), std::make_pair(t, -1));
       it != crowded_pairs.end() && it->first == t; ++it)
    if (member_[static_cast<size_t>(it->second)]) visit(it->second);
}

void TetFaceAdjacency::fill_nodes(const TetMesh& mesh, std::vector<MeshPiece>& pieces) const {
  // A node belongs to the piece of its first tet, and to any other piece it is shared with (a
  // hinge), which then sorts its list.
  std::vector<int> first_piece(mesh.nodes.size(), -1);
  std::vector<std::pair<int, int>> hinges;  // (piece, node) beyond the first
  for (size_t k = 0; k < pieces.size(); ++k)
    for (int t : pieces[k].tets)
      for (int v : mesh.tets[static_cast<size_t>(t)]) {
        int& first = first_piece[static_cast<size_t>(v)];
        if (first < 0)
          first = static_cast<int>(k);
        else if (first != static_cast<int>(k))
          hinges.emplace_back(static_cast<int>(k), v);
      }
  for (size_t v = 0; v < first_piece.size(); ++v)
    if (first_piece[v] >= 0)
      pieces[static_cast<size_t>(first_piece[v])].nodes.push_back(static_cast<int>(v));
  std::sort(hinges.begin(), hinges.end());
  hinges.erase(std::unique(hinges.begin(), hinges.end()), hinges.end());
  for (auto [k, v] : hinges) pieces[static_cast<size_t>(k)].nodes.push_back(v);
  for (size_t k = 0; k < hinges.size(); ++k)
    if (k == 0 || hinges[k].first != hinges[k - 1].first) {
      std::vector<int>& nodes = pieces[static_cast<size_t>(hinges[k].first)].nodes;
      std::sort(nodes.begin(), nodes.end());
    }
}

std::vector<MeshPiece> TetFaceAdjacency::pieces(const TetMesh& mesh) const {
  // A breadth-first walk over the member tets through the faces they share (other_, and the
  // users of a crowded face all with each other, as face_connected_pieces joins them). Pieces
  // come in order of their smallest tet, their tets ascending.
  const std::vector<std::pair<int, int>> crowded = crowded_pairs();
  const size_t tets = member_.size();
  std::vector<int> piece_of(tets, -1), queue;
  queue.reserve(tets);
  int count = 0;
  for (size_t seed = 0; seed < tets; ++seed) {
    if (!member_[seed] || piece_of[seed] >= 0) continue;
    piece_of[seed] = count;
    queue.assign(1, static_cast<int>(seed));
    for (size_t head = 0; head < queue.size(); ++head)
      for_each_neighbour(queue[head], crowded, [&](int u) {
        if (piece_of[static_cast<size_t>(u)] >= 0) return;
        piece_of[static_cast<size_t>(u)] = count;
        queue.push_back(u);
      });
    ++count;
  }
  std::vector<MeshPiece> pieces(static_cast<size_t>(count));
  for (size_t t = 0; t < tets; ++t)
    if (piece_of[t] >= 0)
      pieces[static_cast<size_t>(piece_of[t])].tets.push_back(static_cast<int>(t));
  fill_nodes(mesh, pieces);
  return pieces;
}

std::optional<std::vector<MeshPiece>> TetFaceAdjacency::pieces_cut_off(const TetMesh& mesh,
                                                                       size_t budget) {
  if (!tracking_) return std::nullopt;
  std::vector<int> seeds;
  seeds.swap(changed_since_);
  std::sort(seeds.begin(), seeds.end());
  seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
  // A piece none of these tets is in kept every face it had: it was a piece before, held
  // or anchored as it was. From each seed not yet reached, a walk: it either ends (a whole
  // piece, reached in full), reaches a walk that ran out of budget (the same piece: stop), or
  // runs out itself. Runs-out that never met stay separate "big" walks.
  const std::vector<std::pair<int, int>> crowded = crowded_pairs();
  std::vector<int> walk_of(member_.size(), -1), queue, big_root;  // big_root: per walk
  std::vector<MeshPiece> whole;
  auto root = [&big_root](int w) {  // -1: a whole piece (a walk cannot meet one: it is closed)
    while (w >= 0 && big_root[static_cast<size_t>(w)] != w) w = big_root[static_cast<size_t>(w)];
    return w;
  };
  for (int seed : seeds) {
    if (static_cast<size_t>(seed) >= member_.size() || !member_[static_cast<size_t>(seed)] ||
        walk_of[static_cast<size_t>(seed)] >= 0)
      continue;
    const int w = static_cast<int>(big_root.size());
    big_root.push_back(w);
    walk_of[static_cast<size_t>(seed)] = w;
    queue.assign(1, seed);
    int met = -1;
    size_t head = 0;
    for (; head < queue.size() && queue.size() <= budget && met < 0; ++head)
      for_each_neighbour(queue[head], crowded, [&](int u) {
        const int there = walk_of[static_cast<size_t>(u)];
        if (there == w) return;
        if (there >= 0) {
          met = there;  // an earlier walk that ran out: one piece with it
          return;
        }
        walk_of[static_cast<size_t>(u)] = w;
        queue.push_back(u);
      });
    if (met >= 0 && root(met) >= 0) {
      big_root[static_cast<size_t>(w)] = root(met);
    } else if (head < queue.size() || queue.size() > budget) {
      // ran out of budget: a big walk of its own (for now)
    } else {
      MeshPiece piece;
      piece.tets = queue;
      std::sort(piece.tets.begin(), piece.tets.end());
      whole.push_back(std::move(piece));
      big_root[static_cast<size_t>(w)] = -1;  // whole, not big
    }
  }
  int bigs = 0;
  for (size_t w = 0; w < big_root.size(); ++w) bigs += big_root[w] == static_cast<int>(w);
  if (bigs > 1) return std::nullopt;
  std::sort(whole.begin(), whole.end(),
            [](const MeshPiece& a, const MeshPiece& b) { return a.tets.front() < b.tets.front(); });
  fill_nodes(mesh, whole);
  return whole;
}

}  // namespace stc
