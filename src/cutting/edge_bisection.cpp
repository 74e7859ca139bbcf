#include "cutting/edge_bisection.hpp"

#include <algorithm>

namespace stc {

int bisect_edge(TetMesh& mesh, CutState& state, int a, int b, double t, std::vector<int>& changed) {
  const int m = mesh.num_nodes();
  mesh.nodes.push_back(mesh.nodes[a] + t * (mesh.nodes[b] - mesh.nodes[a]));
  state.locked.push_back(0);
  state.node_tets.emplace_back();
  for (int tet : tets_with_edge(state, a, b)) {
    const Tet parent = mesh.tets[tet];
    const int ia = static_cast<int>(std::find(parent.begin(), parent.end(), a) - parent.begin());
    const int ib = static_cast<int>(std::find(parent.begin(), parent.end(), b) - parent.begin());
    const std::uint8_t bits = mesh.cut_faces[tet];
    // Child 1 (keeps the index): b -> m. Its face opposite a is the new inner face; its face
    // opposite m is the parent's whole face opposite b; the others are halves of parent faces.
    Tet keep = parent;
    keep[ib] = m;
    Tet added = parent;
    added[ia] = m;
    mesh.tets[tet] = keep;
    mesh.cut_faces[tet] = static_cast<std::uint8_t>(bits & ~(1u << ia));
    const int child = mesh.num_tets();
    mesh.tets.push_back(added);
    mesh.cut_faces.push_back(static_cast<std::uint8_t>(bits & ~(1u << ib)));
    state.cuttable.push_back(state.cuttable[tet]);
    state.origin_volume.push_back(state.origin_volume[tet]);
    // Incidence: b leaves the kept child, a is not in the appended one, m and the two other
    // vertices are in both.
    auto& star_b = state.node_tets[b];
    star_b.erase(std::find(star_b.begin(), star_b.end(), tet));
    for (int v : added) state.node_tets[v].push_back(child);
    state.node_tets[m].push_back(tet);
    state.grid.refresh(mesh, tet);  // the kept child's box lies in the parent's
    state.grid.insert(mesh, child);
    changed.push_back(tet);
    changed.push_back(child);
  }
  return m;
}

}  // namespace stc
