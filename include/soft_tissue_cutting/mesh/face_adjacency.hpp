// Which tets of a set share each face, kept up to date as cuts rewrite tets in place and append
// new ones (docs/DESIGN.md section 10, per-step cost). The operation part's boundary and its
// face-connected pieces were found after every cut by matching all of its faces again (a sort
// and a hash of ~10k faces: ~2 ms of the organ liver's cutting step); a cut changes a few dozen
// tets, so only their faces are matched again.
#pragma once

#include "soft_tissue_cutting/mesh/boundary_surface.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

namespace stc {

class TetFaceAdjacency {
 public:
  // The faces of `tets` (indices into mesh.tets), all of them members from now on.
  void build(const TetMesh& mesh, const std::vector<int>& tets);
  // mesh.tets changed: the tets in `changed` were rewritten in place or appended, and every
  // one of them is a member now. Faces of the other members are not looked at.
  void update(const TetMesh& mesh, const std::vector<int>& changed);

  // The members' boundary: the same triangles as extract_boundary_surface of the members
  // alone (tet indices of `mesh`), in the order of their tets and faces.
  BoundarySurface boundary(const TetMesh& mesh) const;
  // The members' face-connected pieces: as face_connected_pieces of the members alone (tet
  // indices of `mesh`), in order of their smallest tet.
  std::vector<MeshPiece> pieces(const TetMesh& mesh) const;
  // Whether update() records the tets pieces_cut_off walks from (off by default, and after
  // build: a user that never asks would keep every changed tet of the session).
  void track_cut_off(bool on) {
    tracking_ = on;
    changed_since_.clear();
  }
  // The pieces the updates since the last call (or track_cut_off) may have cut off, found by
  // walking from the tets whose faces they changed only (docs/DESIGN.md section 10a, "Free
  // pieces"): every piece reached within `budget` tets, each whole, as pieces() gives them. The
  // walks that reach more than `budget` tets must all meet (one piece, the rest of the body: it
  // keeps every node the small pieces do not take); where they do not, nothing is decided
  // and the answer is empty (std::nullopt): then pieces() decides. Not tracking: nullopt.
  std::optional<std::vector<MeshPiece>> pieces_cut_off(const TetMesh& mesh, size_t budget);

 private:
  using Key = std::array<int, 3>;  // sorted node triple
  struct KeyHash {
    size_t operator()(const Key& k) const {
      return (static_cast<size_t>(k[0]) * 73856093u) ^ (static_cast<size_t>(k[1]) * 19349663u) ^
             (static_cast<size_t>(k[2]) * 83492791u);
    }
  };
  struct Face {
    std::vector<int> users;  // 4 * tet + local face
    bool non_manifold = false;
  };
  void add(int tet, const Tet& nodes, std::vector<Key>& touched);
  void remove(int tet, const Tet& nodes, std::vector<Key>& touched);
  void refresh(const Key& key);

  std::unordered_map<Key, Face, KeyHash> faces_;
  std::vector<Tet> seen_;             // each member's nodes as its faces were entered
  std::vector<std::uint8_t> member_;  // per mesh tet
  std::vector<std::uint8_t> users_;   // per 4 * tet + face: how many member tets use that face
  // per 4 * tet + face: the other user's 4 * tet + face where exactly two members share the
  // face, else -1 (pieces() walks these arrays, not the hash map: 47 -> ~10 ms on 71k tets)
  std::vector<int> other_;
  std::vector<Key> crowded_;  // faces of more than two users (non-manifold), sorted
  int non_manifold_ = 0;
  // The members whose faces the updates since the last pieces_cut_off changed, and the other
  // members on those faces (the walks start there).
  std::vector<int> changed_since_;
  bool tracking_ = false;
  // The member tets face-adjacent to t (across a two-user face or a crowded one).
  template <typename Visit>
  void for_each_neighbour(int t, const std::vector<std::pair<int, int>>& crowded_pairs,
                          Visit&& visit) const;
  std::vector<std::pair<int, int>> crowded_pairs() const;
  // Tets ascending -> each piece's nodes, ascending.
  void fill_nodes(const TetMesh& mesh, std::vector<MeshPiece>& pieces) const;
};

}  // namespace stc
