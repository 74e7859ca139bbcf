// Contact of the whole blade with the operation-part surface (docs/DESIGN.md section 7): the edge
// from tip to heel, not only the tip. Stateful: it remembers which surface nodes the blade
// holds from one step to the next. See docs/DESIGN.md (contact).
//
// Edge (belly) contact, per surface node, so it does not depend on which triangle, edge or
// vertex of the surface the edge happens to lie over:
//   - CAPTURE: a node of the deformed operation-part skin (not a node of an incision wall) is
//     captured when the edge LINE passes it between two poses: measured in the blade's plane
//     across the edge (towards the skin's outside), the line was at or above the node at the
//     previous pose and is below it now (or, already below, the blade slid along its length until
//     the node came beside it); the node must lie beside the segment (its projection within
//     tip..heel) and within `lateral_reach` x (its longest surface edge) of the line sideways
//     (along the blade's normal), so exactly the band of nodes under the blade is taken. An edge
//     steeper than `max_edge_slope` to the surface (a plunge along the edge) is left to the tip
//     anchor: it has no belly on the surface.
//   - HOLD: a held node sits ON the blade line: in the blade's plane it is on the line; its
//     sideways offset (along the blade normal), fixed at capture, is kept (so a captured node
//     is not yanked sideways: no force spike). Along the edge it is free: a
//     blade drawn along its length slides under the node, and the indentation follows it.
//   - RELEASE: when the blade has slid past the node (its projection leaves tip..heel), or
//     when the line has withdrawn above the point where the node was touched (measured as
//     at the capture): lifting the blade out lets go.
// Tip contact (tip_contact.hpp) anchors the triangle the tip enters when the blade is steep
// to it (a plunge along the edge, which has no belly on the skin); its three nodes follow the
// tip and take precedence over edge holds.
//
// The simulation imposes the returned displacements as Dirichlet values, solves, and reads
// the reaction at each held node; blade_wrench() turns them into the force and torque on the
// blade.
#pragma once

#include "soft_tissue_cutting/collision/blade.hpp"
#include "soft_tissue_cutting/collision/surface_bvh.hpp"
#include "soft_tissue_cutting/collision/tip_contact.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <vector>

namespace stc {

struct EdgeContactOptions {
  double lateral_reach = 0.6;        // x the node's longest surface edge (>= 1/sqrt(3): no gaps)
  double max_edge_slope = 0.87;      // |edge . n| above this (about 60 deg): no belly contact
  double min_plane_alignment = 0.5;  // blade plane within 60 deg of the skin normal
  double max_entry_depth = 0.15;     // x longest edge: deepest a node the end slides under may be
  double tip_reach = 0.5;            // x blade_length: how deep the tip may be to anchor
  // |edge . n| above this (about 30 deg from the skin): the tip pushes (tip anchor). Below
  // max_edge_slope too, so a blade between 30 and 60 deg presses with both: a plunge along
  // its own edge passes no node with its line, and only the tip can register it.
  double min_tip_slope = 0.5;
};

struct EdgeHeldNode {
  int node = -1;
  Vec3 offset_blade = Vec3::Zero();   // sideways offset from the line, blade frame (0, y, 0)
  Vec3 touch_point = Vec3::Zero();    // deformed position when captured
  Vec3 touch_normal = Vec3::UnitZ();  // the outward direction its depth was measured along
};

class EdgeContact {
 public:
  explicit EdgeContact(EdgeContactOptions options = {}) : options_(options) {}

  // One step: the blade moved from `previous` (none: its first pose) to `edge`; `bvh` holds
  // the deformed surface of the last solve (refit), `u` that solve's displacement (3n).
  // Returns the imposed displacement of every node the blade holds now (node -> u).
  std::map<int, Vec3> update(const SurfaceBvh& bvh, const TetMesh& mesh, const Eigen::VectorXd& u,
                             const std::optional<BladeEdge>& previous, const BladeEdge& edge);
  // Let go of everything (no blade, or the tissue yielded and the blade cuts now).
  void release();

  bool empty() const { return held_.empty() && !tip_anchor_; }
  const std::vector<EdgeHeldNode>& edge_nodes() const { return held_; }
  const std::optional<ContactAnchor>& tip_anchor() const { return tip_anchor_; }

 private:
  EdgeContactOptions options_;
  std::vector<EdgeHeldNode> held_;  // ascending by node
  std::optional<ContactAnchor> tip_anchor_;
};

// Force and torque on the blade from the tissue: the reaction that holds node k is
// `holding_force[k]` (K u - f there), so the tissue pushes the blade with minus it, at
// `held_position[k]` (deformed). Torque about the tip, in the frame the inputs are in.
struct BladeWrench {
  Vec3 force = Vec3::Zero();
  Vec3 torque = Vec3::Zero();
};
BladeWrench blade_wrench(const Vec3& tip, const std::vector<Vec3>& held_position,
                         const std::vector<Vec3>& holding_force);

// The same wrench expressed in the blade's frame (x along the edge, y the blade normal).
BladeWrench in_blade_frame(const BladeWrench& w, const BladeEdge& edge);

// Does any part of the edge lie in the tissue? `inside(p)` answers for a point; the edge is
// sampled every `spacing` (at least tip, middle and heel).
template <class Inside>
bool edge_in_tissue(const BladeEdge& edge, double spacing, Inside inside) {
  const double length = (edge.heel - edge.tip).norm();
  const int n = std::max(2, static_cast<int>(std::ceil(length / std::max(spacing, 1e-12))));
  for (int k = 0; k <= n; ++k)
    if (inside(edge.tip + (static_cast<double>(k) / n) * (edge.heel - edge.tip))) return true;
  return false;
}

// Area of the sweep between two edge positions (the two triangles cut_sweep inserts).
double sweep_area(const BladeEdge& from, const BladeEdge& to);

// How much of the sweep from `from` to `to` lies in the sweeps between consecutive edges of
// `stroke` (0..1, by area; 0 for a sweep narrower than `tolerance` x the blade length across
// the edge, which sweeps nothing: a blade held still or moved along its own edge): 1 when the
// blade moves back through the incision it has just cut. Points count as covered within
// `tolerance` x the blade length of an earlier sweep triangle.
// below > 0: the caller only asks whether the fraction reaches `below`; once enough of the sweep
// is found uncovered that it cannot (by a margin far above rounding), some value under `below`
// is returned without measuring the rest (a blade cutting forward: most steps).
double swept_before_fraction(const std::vector<BladeEdge>& stroke, const BladeEdge& from,
                             const BladeEdge& to, double tolerance = 1e-4, double below = 0);

}  // namespace stc
