#include "cutting/node_moves.hpp"

#include "cutting/triangle_cut.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <algorithm>
#include <cmath>

namespace stc {

NodeMove how_node_may_move(const TetMesh& mesh, const CutState& state, int v, Vec3& axis) {
  if (state.locked[v]) return NodeMove::kNone;
  // The fan: faces touching v with no neighbour, as (w1, w2) with (v, w1, w2) facing out.
  std::vector<std::array<int, 2>> fan;
  Vec3 area = Vec3::Zero();
  double scale = 0;
  bool on_cut = false;
  for (int t : state.node_tets[v]) {
    if (!state.cuttable[t]) return NodeMove::kNone;
    const Tet& k = mesh.tets[t];
    for (int f = 0; f < 4; ++f) {
      if (k[f] == v) continue;  // the face opposite v does not touch it
      const bool open = neighbour_across(mesh, state, t, f).first < 0;
      on_cut = on_cut || mesh.is_cut_face(t, f);
      if (!open) {
        if (mesh.is_cut_face(t, f)) return NodeMove::kNone;  // a cut that has not opened here
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
  if (fan.empty()) return on_cut ? NodeMove::kNone : NodeMove::kInsideStar;
  if (!(area.norm() > 0)) return NodeMove::kNone;
  // The fan's faces in the plane through v with unit normal n, facing along n: all of them
  // (kInPlane), or all but those in a second such plane (kOnLine, the crease where a cut's wall
  // meets another wall or a flat skin).
  const auto in_plane = [&](const std::array<int, 2>& face, const Vec3& n) {
    const Vec3 m = (mesh.nodes[face[0]] - mesh.nodes[v]).cross(mesh.nodes[face[1]] - mesh.nodes[v]);
    if (!(m.dot(n) > 0)) return false;
    for (int w : face)
      if (std::abs(n.dot(mesh.nodes[w] - mesh.nodes[v])) > 1e-9 * scale) return false;
    return true;
  };
  const auto face_normal = [&](const std::array<int, 2>& face) -> Vec3 {
    return (mesh.nodes[face[0]] - mesh.nodes[v])
        .cross(mesh.nodes[face[1]] - mesh.nodes[v])
        .normalized();
  };
  NodeMove kind = NodeMove::kNone;
  axis = area.normalized();
  if (std::all_of(fan.begin(), fan.end(), [&](const auto& f) { return in_plane(f, axis); })) {
    kind = NodeMove::kInPlane;
  } else {
    const Vec3 first = face_normal(fan.front());
    std::vector<std::array<int, 2>> rest;
    for (const auto& f : fan)
      if (!in_plane(f, first)) rest.push_back(f);
    if (rest.empty()) return NodeMove::kNone;
    const Vec3 second = face_normal(rest.front());
    const Vec3 line = first.cross(second);
    // Two planes at an angle (a line well defined), every other face in the second one.
    if (!(line.norm() > 1e-3) ||
        !std::all_of(rest.begin(), rest.end(), [&](const auto& f) { return in_plane(f, second); }))
      return NodeMove::kNone;
    axis = line.normalized();
    kind = NodeMove::kOnLine;
  }
  // One fan: its faces chained w1 -> w2 make a single cycle.
  int at = fan.front()[1];
  const int start = fan.front()[0];
  size_t walked = 1;
  while (at != start && walked < fan.size()) {
    auto it = std::find_if(fan.begin(), fan.end(),
                           [at](const std::array<int, 2>& e) { return e[0] == at; });
    if (it == fan.end()) return NodeMove::kNone;
    at = (*it)[1];
    ++walked;
  }
  return at == start && walked == fan.size() ? kind : NodeMove::kNone;
}

bool may_move_inside_star(const TetMesh& mesh, const CutState& state, int v) {
  Vec3 unused;
  return how_node_may_move(mesh, state, v, unused) == NodeMove::kInsideStar;
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
