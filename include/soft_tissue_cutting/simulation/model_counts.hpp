// The counts of a simulation, in one chain: HybridModel::counts() gives the model's sizes,
// Simulation::counts() extends them with the run's totals (no field copied by hand), and the
// stats JSON of `tissue solve` and the bench summary write the sizes through one function
// (model_counts_json.hpp). Names as docs/SCENE.md "Offline run" has them.
#pragma once

namespace stc {

// Sizes of the hybrid model; fixed nodes count in their set.
struct HybridModelCounts {
  int nodes = 0, tets = 0;
  int dof_operation = 0;  // rows of the hybrid system: free DOFs of O u I
  int nodes_operation = 0, nodes_interface = 0, nodes_surface_condensed = 0,
      nodes_interior_condensed = 0;
};

// The sizes of the current state (after cuts) plus the totals since the start (or reset).
struct ModelCounts : HybridModelCounts {
  int cuts = 0, tets_split = 0, free_pieces_held = 0;
  // Shape upkeep after each stroke (docs/DESIGN.md section 8, "Smooth" and "Flip"): nodes the
  // smoothing moved, flips made (2-3 face flips and edge removals).
  int nodes_smoothed = 0, flips = 0;
  long cg_iterations_total = 0;  // every CG iteration since the start (or the last reset)
  long solver_fallbacks = 0;     // gl solves finished on the cpu since the start (or reset)
  double volume_initial = 0, volume_final = 0;
};

}  // namespace stc
