// Contact between the blade tip and the surface of the operation part (METHOD 5 steps 2-3).
//
// Model: when the tip first enters the deformed surface of the operation part, the material
// point it touches (a point of a surface triangle, kept in REST coordinates) is anchored to
// the tip. While the blade presses, the three nodes of that triangle are imposed the
// displacement that carries the anchored material point onto the tip (the triangle
// translates with the blade), and the tissue's reaction on the blade is minus the force the
// solve needs at those nodes. The contact ends when the tip withdraws above the anchored
// triangle's rest plane. A pure plunge therefore presses; the blade cuts only once the
// reaction exceeds `cut_pressure` (SPEC 3).
#pragma once

#include "soft_tissue_cutting/mesh/boundary_surface.hpp"

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace stc {

struct ContactAnchor {
  Tri nodes;            // the touched surface triangle
  Vec3 material_point;  // rest position of the touched point
  Vec3 rest_normal;     // outward unit normal of the triangle at rest
};

// The first contact of `tip` with the surface triangles (deformed positions x + u): the
// triangle whose deformed plane the tip lies beneath, nearest to the tip, within `reach`
// (the tip must be inside the tissue, within reach of the surface). Uses `triangles` as
// given: pass the operation part's boundary triangles.
std::optional<ContactAnchor> find_contact(const TetMesh& mesh, const Eigen::VectorXd& u,
                                          const std::vector<BoundaryTriangle>& triangles,
                                          const Vec3& tip, double reach);

// The imposed displacement of the anchor's nodes for the blade tip at `tip`, or nothing when
// the tip has withdrawn above the anchored triangle's rest plane (contact released).
std::optional<Vec3> anchored_displacement(const ContactAnchor& anchor, const Vec3& tip);

}  // namespace stc
