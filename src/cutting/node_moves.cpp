#include "cutting/node_moves.hpp"

#include "cutting/triangle_cut.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <algorithm>
#include <cmath>

namespace stc {

bool may_move_inside_star(const TetMesh& mesh, const CutState& state, int v) {
  if (state.locked[v]) return false;
  for (int t : state.node_tets[v]) {
    if (!state.cuttable[t]) return false;
    for (int f = 0; f < 4; ++f) {
      if (mesh.tets[t][f] == v) continue;                               // opposite v
      if (mesh.is_cut_face(t, f)) return false;                         // on a cut
      if (neighbour_across(mesh, state, t, f).first < 0) return false;  // on the boundary
    }
  }
  return true;
}

bool may_slide_on_plane(const TetMesh& mesh, const CutState& state, int v, Vec3& normal) {
  if (state.locked[v]) return false;
  // The fan: faces touching v with no neighbour, as (w1, w2) with (v, w1, w2) facing out.
  std::vector<std::array<int, 2>> fan;
  Vec3 area = Vec3::Zero();
  double scale = 0;
  for (int t : state.node_tets[v]) {
    if (!state.cuttable[t]) return false;
    const Tet& k = mesh.tets[t];
    for (int f = 0; f < 4; ++f) {
      if (k[f] == v) continue;
      const bool open = neighbour_across(mesh, state, t, f).first < 0;
      if (!open) {
        if (mesh.is_cut_face(t, f)) return false;  // a cut that has not opened here
        continue;
      }
      std::array<int, 3> face = {k[kTetFaces[f][0]], k[kTetFaces[f][1]], k[kTetFaces[f][2]]};
      while (face[0] != v) std::rotate(face.begin(), face.begin() + 1, face.end());
      fan.push_back({face[1], face[2]});
      const Vec3 &x = mesh.nodes[v], &a = mesh.nodes[face[1]], &b = mesh.nodes[face[2]];
      area += (a - x).cross(b - x);
      scale = std::max({scale, (a - x).norm(), (b - x).norm()});
    }
  }
  if (fan.empty() || !(area.norm() > 0)) return false;
  normal = area.normalized();
  // Flat and facing one way.
  for (const auto& [a, b] : fan) {
    const Vec3 n = (mesh.nodes[a] - mesh.nodes[v]).cross(mesh.nodes[b] - mesh.nodes[v]);
    if (!(n.dot(normal) > 0)) return false;
    for (int w : {a, b})
      if (std::abs(normal.dot(mesh.nodes[w] - mesh.nodes[v])) > 1e-9 * scale) return false;
  }
  // One fan: its faces chained w1 -> w2 make a single cycle.
  std::vector<std::array<int, 2>> chain = fan;
  int at = chain.front()[1];
  const int first = chain.front()[0];
  size_t walked = 1;
  while (at != first && walked < chain.size()) {
    auto it = std::find_if(chain.begin(), chain.end(),
                           [at](const std::array<int, 2>& e) { return e[0] == at; });
    if (it == chain.end()) return false;
    at = (*it)[1];
    ++walked;
  }
  return at == first && walked == chain.size();
}

double star_smallest_dihedral(const TetMesh& mesh, const CutState& state, int v, const Vec3& x,
                              double guard) {
  double smallest = 180;
  for (int t : state.node_tets[v]) {
    const Tet& k = mesh.tets[t];
    const Vec3* p[4];
    for (int i = 0; i < 4; ++i) p[i] = k[i] == v ? &x : &mesh.nodes[k[i]];
    if (!(signed_volume(*p[0], *p[1], *p[2], *p[3]) > guard * state.origin_volume[t])) return -1;
    smallest = std::min(smallest, smallest_dihedral_deg(*p[0], *p[1], *p[2], *p[3]));
  }
  return smallest;
}

double star_longest_edge(const TetMesh& mesh, const CutState& state, int v) {
  double longest = 0;
  for (int t : state.node_tets[v])
    for (int w : mesh.tets[t]) longest = std::max(longest, (mesh.nodes[w] - mesh.nodes[v]).norm());
  return longest;
}

void move_node(TetMesh& mesh, CutState& state, int v, const Vec3& x, CutResult& result) {
  mesh.nodes[v] = x;
  state.longest_edge_bound = std::max(state.longest_edge_bound, star_longest_edge(mesh, state, v));
  for (int t : state.node_tets[v]) {
    state.grid.insert(mesh, t);  // its box may have grown
    result.changed_tets.push_back(t);
  }
  result.moved_nodes.push_back(v);
}

}  // namespace stc
