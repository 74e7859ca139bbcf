#include "cutting/cut_state.hpp"

#include <algorithm>
#include <stdexcept>

namespace stc {

CutState make_cut_state(TetMesh& mesh, std::vector<std::uint8_t> locked,
                        std::vector<std::uint8_t> cuttable) {
  CutState state;
  if (locked.empty()) locked.assign(mesh.nodes.size(), 0);
  if (cuttable.empty()) cuttable.assign(mesh.tets.size(), 1);
  if (locked.size() != mesh.nodes.size() || cuttable.size() != mesh.tets.size())
    throw std::invalid_argument("make_cut_state: locked/cuttable sizes do not match the mesh");
  if (mesh.cut_faces.size() != mesh.tets.size()) mesh.cut_faces.assign(mesh.tets.size(), 0);
  state.locked = std::move(locked);
  state.cuttable = std::move(cuttable);
  state.node_tets.assign(mesh.nodes.size(), {});
  state.origin_volume.resize(mesh.tets.size());
  for (int t = 0; t < mesh.num_tets(); ++t) {
    state.origin_volume[t] = tet_volume(mesh, t);
    const Tet& k = mesh.tets[t];
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        state.longest_edge_bound =
            std::max(state.longest_edge_bound, (mesh.nodes[k[i]] - mesh.nodes[k[j]]).norm());
    for (int v : mesh.tets[t]) {
      state.node_tets[v].push_back(t);
      if (!state.cuttable[t]) state.locked[v] = 1;
    }
  }
  state.grid.build(mesh, state.cuttable);
  return state;
}

std::vector<int> tets_with_edge(const CutState& state, int a, int b) {
  const auto& ta = state.node_tets[a];
  const auto& tb = state.node_tets[b];
  std::vector<int> shared;
  // Stars are small (tens of tets): a quadratic intersection beats sorting.
  for (int t : ta)
    if (std::find(tb.begin(), tb.end(), t) != tb.end()) shared.push_back(t);
  std::sort(shared.begin(), shared.end());
  return shared;
}

}  // namespace stc
