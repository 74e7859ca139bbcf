// docs/SCENE.md "Cut invariants" as a check: what every cut must leave behind. Used by the tests
// after every sweep and available to the simulation as a debug assertion.
#pragma once

#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

#include <string>
#include <vector>

namespace stc {

struct InvariantLimits {
  double initial_volume = 0;
  // Every tet's volume must exceed this fraction of its size class. The cutter's guard
  // (CutOptions::min_volume_fraction) enforces it by construction; checked with a 1e-9
  // relative allowance for round-off in recomputing volumes from positions.
  double min_volume_fraction = 0.01;
  double volume_relative_tolerance = 1e-9;
};

// size_class: per tet, e.g. CutState::origin_volume. Returns the violated invariants, one
// human-readable line each; empty when all hold. (K's positive definiteness on the free DOF
// is the assembly's to check; free pieces: free_pieces.hpp.)
std::vector<std::string> check_cut_invariants(const TetMesh& mesh,
                                              const std::vector<double>& size_class,
                                              const InvariantLimits& limits);

}  // namespace stc
