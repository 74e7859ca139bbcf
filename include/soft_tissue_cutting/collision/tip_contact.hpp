// Contact between the blade tip and the surface of the operation part (docs/DESIGN.md section 7).
//
// Model: when the tip first enters the deformed surface of the operation part, the surface
// triangle it touches is anchored to the tip. While the blade presses, that triangle's three
// nodes follow the tip from where they were at the touch (each node's displacement at the
// touch plus the tip's motion since), and the tissue's reaction on the blade is minus the
// force the solve needs at those nodes. The contact ends when the tip withdraws above the point it
// first touched (the deformed surface at that moment), along that surface's normal. A pure plunge
// therefore presses; the blade cuts only once the reaction exceeds `cut_pressure` (docs/SCENE.md
// "Scene file").
#pragma once

#include "soft_tissue_cutting/mesh/boundary_surface.hpp"

#include <Eigen/Core>

#include <array>
#include <optional>
#include <vector>

namespace stc {

struct ContactAnchor {
  Tri nodes;                               // the touched surface triangle
  std::array<Vec3, 3> touch_displacement;  // the nodes' displacements at the touch
  Vec3 touch_point;                        // where the tip met the deformed surface
  Vec3 touch_normal;                       // outward unit normal of the deformed triangle there
};

// The first contact of `tip` with the surface triangles (deformed positions x + u): the
// triangle whose deformed plane the tip lies beneath, nearest to the tip, within `reach`
// (the tip must be inside the tissue, within reach of the surface). Uses `triangles` as
// given: pass the operation part's boundary triangles.
std::optional<ContactAnchor> find_contact(const TetMesh& mesh, const Eigen::VectorXd& u,
                                          const std::vector<BoundaryTriangle>& triangles,
                                          const Vec3& tip, double reach);

// The imposed displacements of the anchor's nodes for the blade tip at `tip`, or nothing
// when the tip has withdrawn above the point it first touched (contact released).
std::optional<std::array<Vec3, 3>> anchored_displacements(const ContactAnchor& anchor,
                                                          const Vec3& tip);

}  // namespace stc
