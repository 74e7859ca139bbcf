#include "cutting/node_moves.hpp"

#include "cutting/cut_state.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <algorithm>
#include <cmath>

namespace stc {

NodeMove how_node_may_move(const TetMesh& mesh, const CutState& state, int v, Vec3& axis) {
  if (state.locked[v]) return NodeMove::kNone;
  // The faces touching v that must stay where they are, as (w1, w2) with (v, w1, w2) facing
  // out of the tet: those with no neighbour (the fan) and the cuts that have not opened.
  std::vector<std::array<int, 2>> fan, closed;
  double scale = 0;
  const std::vector<std::array<int, 4>> across = star_neighbours(mesh, state, v);
  for (size_t s = 0; s < across.size(); ++s) {
    const int t = state.node_tets[v][s];
    if (!state.cuttable[t]) return NodeMove::kNone;
    const Tet& k = mesh.tets[t];
    for (int f = 0; f < 4; ++f) {
      if (k[f] == v) continue;  // the face opposite v does not touch it
      const bool open = across[s][f] < 0;
      if (!open && !mesh.is_cut_face(t, f)) continue;
      std::array<int, 3> face = {k[kTetFaces[f][0]], k[kTetFaces[f][1]], k[kTetFaces[f][2]]};
      while (face[0] != v) std::rotate(face.begin(), face.begin() + 1, face.end());
      (open ? fan : closed).push_back({face[1], face[2]});
      scale = std::max({scale, (mesh.nodes[face[1]] - mesh.nodes[v]).norm(),
                        (mesh.nodes[face[2]] - mesh.nodes[v]).norm()});
    }
  }
  if (fan.empty() && closed.empty()) return NodeMove::kInsideStar;
  const Vec3& x = mesh.nodes[v];
  const auto normal_of = [&](const std::array<int, 2>& face) -> Vec3 {
    return (mesh.nodes[face[0]] - x).cross(mesh.nodes[face[1]] - x);
  };
  const auto lies_in = [&](const std::array<int, 2>& face, const Vec3& n) {
    for (int w : face)
      if (std::abs(n.dot(mesh.nodes[w] - x)) > 1e-9 * scale) return false;
    return true;
  };
  // The planes through v (unit normals) that hold those faces, to round-off (1e-9 of the
  // star's scale): one (kInPlane: a flat fan or cut), or two at an angle (kOnLine: the crease
  // where a cut meets another cut or a flat stretch of the tissue's surface); the open faces
  // of one plane all face one way.
  std::vector<Vec3> planes;
  std::vector<Vec3> area;   // per plane: its faces' area vectors, summed along planes[p]
  std::vector<int> facing;  // per plane: +1 / -1 the open faces' side, 0 none yet
  for (const auto* faces : {&fan, &closed})
    for (const auto& face : *faces) {
      const Vec3 n = normal_of(face);
      size_t p = 0;
      while (p < planes.size() && !lies_in(face, planes[p])) ++p;
      if (p == planes.size()) {
        if (!(n.norm() > 0) || planes.size() == 2) return NodeMove::kNone;
        planes.push_back(n.normalized());
        area.push_back(Vec3::Zero());
        facing.push_back(0);
      }
      const int side = n.dot(planes[p]) > 0 ? 1 : -1;
      area[p] += side * n;
      if (faces == &closed) continue;
      if (facing[p] != 0 && facing[p] != side) return NodeMove::kNone;
      facing[p] = side;
    }
  // Each plane's normal from all its faces (the first face alone may be a sliver's, its
  // normal off by more than round-off).
  for (size_t p = 0; p < planes.size(); ++p) planes[p] = area[p].normalized();
  NodeMove kind = NodeMove::kInPlane;
  axis = planes[0];
  if (planes.size() == 2) {
    const Vec3 line = planes[0].cross(planes[1]);
    if (!(line.norm() > 1e-3)) return NodeMove::kNone;  // nearly parallel: no line to keep
    axis = line.normalized();
    kind = NodeMove::kOnLine;
  }
  if (fan.empty()) return kind;
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
