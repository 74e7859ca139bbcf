#include "soft_tissue_cutting/mesh/boundary_surface.hpp"

#include <algorithm>
#include <unordered_map>

namespace stc {
namespace {

std::uint64_t edge_key(int a, int b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}

struct FaceUse {
  int tet;
  int face;
};

}  // namespace

BoundarySurface extract_boundary_surface(const TetMesh& mesh) {
  // Key each face by its sorted node triple; a boundary face is used by exactly one tet.
  // One flat array sorted by key (rather than a map) keeps this cheap enough to redo after
  // every cut.
  struct FaceEntry {
    std::array<int, 3> key;
    int tet;
    int face;
    bool operator<(const FaceEntry& o) const {
      return key != o.key ? key < o.key : (tet != o.tet ? tet < o.tet : face < o.face);
    }
  };
  std::vector<FaceEntry> faces;
  faces.reserve(4 * mesh.tets.size());
  for (int t = 0; t < mesh.num_tets(); ++t) {
    for (int f = 0; f < 4; ++f) {
      std::array<int, 3> key = {mesh.tets[t][kTetFaces[f][0]], mesh.tets[t][kTetFaces[f][1]],
                                mesh.tets[t][kTetFaces[f][2]]};
      std::sort(key.begin(), key.end());
      faces.push_back({key, t, f});
    }
  }
  std::sort(faces.begin(), faces.end());
  BoundarySurface surface;
  for (size_t i = 0; i < faces.size();) {
    size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    const FaceUse first{faces[i].tet, faces[i].face};
    if (j - i == 1) {
      const Tet& tet = mesh.tets[first.tet];
      const auto& lf = kTetFaces[first.face];
      surface.triangles.push_back({Tri{tet[lf[0]], tet[lf[1]], tet[lf[2]]}, first.tet, first.face,
                                   mesh.is_cut_face(first.tet, first.face)});
    } else if (j - i > 2) {
      ++surface.non_manifold_faces;
    } else {
      // Two users of a face must wind it in opposite directions (tets on both sides).
      const Tet& a = mesh.tets[first.tet];
      const Tet& b = mesh.tets[faces[i + 1].tet];
      const auto& fa = kTetFaces[first.face];
      const auto& fb = kTetFaces[faces[i + 1].face];
      const Tri ta = {a[fa[0]], a[fa[1]], a[fa[2]]};
      const Tri tb = {b[fb[0]], b[fb[1]], b[fb[2]]};
      // Same orientation iff tb is a rotation of ta.
      bool same = false;
      for (int r = 0; r < 3; ++r)
        same |= (tb[0] == ta[r] && tb[1] == ta[(r + 1) % 3] && tb[2] == ta[(r + 2) % 3]);
      if (same) ++surface.non_manifold_faces;
    }
    i = j;
  }
  return surface;
}

std::vector<int> boundary_nodes(const BoundarySurface& surface) {
  std::vector<int> nodes;
  nodes.reserve(surface.triangles.size() * 3);
  for (const auto& tri : surface.triangles)
    nodes.insert(nodes.end(), tri.nodes.begin(), tri.nodes.end());
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

bool is_closed_oriented_manifold(const BoundarySurface& surface) {
  if (surface.non_manifold_faces != 0) return false;
  // Each directed edge used once, and its reverse used once.
  std::unordered_map<std::uint64_t, int> directed;
  directed.reserve(surface.triangles.size() * 3);
  for (const auto& tri : surface.triangles) {
    for (int e = 0; e < 3; ++e) {
      if (++directed[edge_key(tri.nodes[e], tri.nodes[(e + 1) % 3])] > 1) return false;
    }
  }
  for (const auto& [key, count] : directed) {
    const int a = static_cast<int>(key >> 32);
    const int b = static_cast<int>(key & 0xffffffffu);
    if (directed.find(edge_key(b, a)) == directed.end()) return false;
  }
  return true;
}

}  // namespace stc
