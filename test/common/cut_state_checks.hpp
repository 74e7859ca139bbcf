// Checks of the cutter's state after its tets were replaced (a flip, an insertion, a star), for
// the unit tests of src/cutting/ (header only: those tests see the cutter's own headers).
#pragma once

#include "cutting/cut_state.hpp"

#include <algorithm>
#include <string>

namespace stc::test {

// Does the cut state follow the mesh: every tet in its corners' stars and only there, one star
// and one lock flag per node? Empty if so, else what does not.
inline std::string stars_mismatch(const TetMesh& mesh, const CutState& state) {
  if (state.node_tets.size() != static_cast<size_t>(mesh.num_nodes()) ||
      state.locked.size() != static_cast<size_t>(mesh.num_nodes()))
    return "one star and one lock flag per node expected";
  size_t incidences = 0;
  for (int v = 0; v < mesh.num_nodes(); ++v)
    for (int t : state.node_tets[static_cast<size_t>(v)]) {
      const Tet& e = mesh.tets[static_cast<size_t>(t)];
      if (std::find(e.begin(), e.end(), v) == e.end())
        return "node " + std::to_string(v) + "'s star holds tet " + std::to_string(t);
      ++incidences;
    }
  if (incidences != 4 * mesh.tets.size())
    return std::to_string(incidences) + " star entries for " + std::to_string(mesh.tets.size()) +
           " tets";
  return "";
}

}  // namespace stc::test
