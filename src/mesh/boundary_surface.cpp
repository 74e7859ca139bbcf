#include "soft_tissue_cutting/mesh/boundary_surface.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
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

std::vector<KeyedFace> faces_by_key(const TetMesh& mesh) {
  // Two passes: a counting sort on the smallest node, then each node's few faces sorted by the
  // other two. One std::sort of every face (with std::array's memcmp comparisons) took 61 ms
  // on the organ liver's 284k faces, this 15-18 ms; a region move extracts two surfaces.
  const size_t nodes = mesh.nodes.size();
  auto sorted_key = [&mesh](int t, int f) {
    std::array<int, 3> key = {mesh.tets[t][kTetFaces[f][0]], mesh.tets[t][kTetFaces[f][1]],
                              mesh.tets[t][kTetFaces[f][2]]};
    if (key[0] > key[1]) std::swap(key[0], key[1]);
    if (key[1] > key[2]) std::swap(key[1], key[2]);
    if (key[0] > key[1]) std::swap(key[0], key[1]);
    return key;
  };
  std::vector<int> start(nodes + 1, 0);
  for (int t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f) {
      const std::array<int, 3> key = sorted_key(t, f);
      if (key[0] < 0 || static_cast<size_t>(key[2]) >= nodes)
        throw std::invalid_argument("faces_by_key: tetrahedron " + std::to_string(t) +
                                    " refers to a node outside the mesh");
      ++start[static_cast<size_t>(key[0]) + 1];
    }
  for (size_t v = 0; v < nodes; ++v) start[v + 1] += start[v];
  std::vector<KeyedFace> faces(static_cast<size_t>(start[nodes]));
  std::vector<int> next(start.begin(), start.end() - 1);
  for (int t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f) {
      const std::array<int, 3> key = sorted_key(t, f);
      faces[static_cast<size_t>(next[static_cast<size_t>(key[0])]++)] = {key, t, f};
    }
  for (size_t v = 0; v < nodes; ++v)
    std::sort(faces.begin() + start[v], faces.begin() + start[v + 1],
              [](const KeyedFace& a, const KeyedFace& b) {
                if (a.key[1] != b.key[1]) return a.key[1] < b.key[1];
                if (a.key[2] != b.key[2]) return a.key[2] < b.key[2];
                return a.tet < b.tet;
              });
  return faces;
}

BoundarySurface extract_boundary_surface(const TetMesh& mesh) {
  // A boundary face is used by exactly one tet.
  const std::vector<KeyedFace> faces = faces_by_key(mesh);
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
