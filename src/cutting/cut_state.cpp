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

std::vector<std::array<int, 4>> star_neighbours(const TetMesh& mesh, const CutState& state, int v) {
  const std::vector<int>& star = state.node_tets[v];
  std::vector<std::array<int, 4>> across(star.size(), {-1, -1, -1, -1});
  // A face through v is named by its two other corners; its two tets list the same pair.
  std::vector<std::pair<std::uint64_t, int>> faces;  // (pair, 4 k + f)
  faces.reserve(3 * star.size());
  for (size_t k = 0; k < star.size(); ++k) {
    const Tet& t = mesh.tets[star[k]];
    for (int f = 0; f < 4; ++f) {
      if (t[f] == v) continue;  // the face opposite v
      std::array<std::uint32_t, 2> other;
      int n = 0;
      for (int c = 0; c < 3; ++c)
        if (const int w = t[kTetFaces[f][c]]; w != v) other[n++] = static_cast<std::uint32_t>(w);
      if (other[0] > other[1]) std::swap(other[0], other[1]);
      faces.emplace_back((static_cast<std::uint64_t>(other[0]) << 32) | other[1],
                         static_cast<int>(4 * k) + f);
    }
  }
  std::sort(faces.begin(), faces.end());
  for (size_t i = 0; i + 1 < faces.size(); ++i)
    if (faces[i].first == faces[i + 1].first) {
      const int a = faces[i].second, b = faces[i + 1].second;
      across[a / 4][a % 4] = b / 4;
      across[b / 4][b % 4] = a / 4;
      ++i;
    }
  return across;
}

}  // namespace stc
