// The visible deformed surface, and a snapshot of what it is drawn from that can be turned
// into it later on another thread. Simulation::surface_snapshot() only copies (rest
// positions, the displacement, the surface triangles) and shares the condensed part, so the
// caller's lock is held briefly; SurfaceSnapshot::compute() then recovers u_S from u_I (one
// sparse solve through the factor of K2_NN, docs/DESIGN.md eq. (13)) without the Simulation,
// which may meanwhile step, cut, move its region or be reset: the snapshot shows the state it
// was taken at. The ROS node recovers on its display thread this way, never inside a step.
#pragma once

#include "soft_tissue_cutting/mesh/boundary_surface.hpp"
#include "soft_tissue_cutting/recovery/surface_recovery.hpp"

#include <cstdint>
#include <vector>

namespace stc {

// The visible deformed surface: operation-part surface including cut faces, plus the
// condensed surface S (docs/DESIGN.md eq. (12)).
struct DeformedSurface {
  std::vector<Vec3> positions;       // deformed position of every mesh node
  std::vector<double> displacement;  // |u| per node, m
  std::vector<BoundaryTriangle> triangles;
};

struct SurfaceSnapshot {
  std::uint64_t version = 0;          // Simulation::surface_version() when taken
  std::vector<Vec3> rest;             // rest position of every mesh node
  DisplacementSnapshot displacement;  // every node; S and Q recovered by compute()
  std::vector<BoundaryTriangle> triangles;

  // The deformed surface at the time of the snapshot, on any thread. Recovers u_S (and u_Q)
  // into `displacement` first when u_I moved since the model's last recovery (the only costly
  // part); Simulation::adopt_recovery can then hand that recovery back to the model.
  DeformedSurface compute();
};

}  // namespace stc
