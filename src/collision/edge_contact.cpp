#include "soft_tissue_cutting/collision/edge_contact.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

namespace stc {
namespace {

// The blade's frame: columns x = edge direction (tip -> heel), y = blade normal, z = x cross y.
Eigen::Matrix3d blade_frame(const BladeEdge& edge) {
  Eigen::Matrix3d r;
  const Vec3 x = (edge.heel - edge.tip).normalized();
  const Vec3 y = (edge.normal - edge.normal.dot(x) * x).normalized();
  r.col(0) = x;
  r.col(1) = y;
  r.col(2) = x.cross(y);
  return r;
}

// What a surface node looks like locally: area-weighted outward normal of its skin
// triangles, its longest surface edge, and whether the blade may hold it (every triangle
// around it is operation-part skin: no incision wall, no condensed surface).
struct NodeLocal {
  Vec3 normal = Vec3::Zero();
  double longest_edge = 0;
  bool holdable = true;
};

}  // namespace

std::map<int, Vec3> EdgeContact::update(const SurfaceBvh& bvh, const TetMesh& mesh,
                                        const Eigen::VectorXd& u,
                                        const std::optional<BladeEdge>& previous,
                                        const BladeEdge& edge) {
  const double length = (edge.heel - edge.tip).norm();
  const Eigen::Matrix3d frame = blade_frame(edge);
  const Vec3 e = frame.col(0);
  std::map<int, Vec3> imposed;

  // The tip: anchor the triangle it enters, or follow the one it holds.
  if (!tip_anchor_) {
    const double reach = options_.tip_reach * length;
    std::vector<BoundaryTriangle> near;
    for (int t : bvh.near_segment(edge.tip, edge.tip, reach))
      if (bvh.is_operation(t)) near.push_back(bvh.surface().triangles[t]);
    tip_anchor_ = find_contact(mesh, u, near, edge.tip, reach);
    // Only a steep blade pushes with its tip; a blade lying on the skin presses with its
    // edge (below), and its tip is just the end of that line. Steep means min_tip_slope, not
    // max_edge_slope: a vertical blade plunged into a sagged slope (37 deg from its normal)
    // entered with its tip and registered no contact at all (its line passes no node).
    if (tip_anchor_ && std::abs(e.dot(tip_anchor_->touch_normal)) <= options_.min_tip_slope)
      tip_anchor_.reset();
  }
  if (tip_anchor_) {
    if (const auto held = anchored_displacements(*tip_anchor_, edge.tip)) {
      for (int k = 0; k < 3; ++k) imposed[tip_anchor_->nodes[k]] = (*held)[k];
    } else {
      tip_anchor_.reset();
    }
  }

  // Nodes held on the line: slide along the edge, keep their sideways offset, or let go.
  std::vector<EdgeHeldNode> kept;
  for (const EdgeHeldNode& h : held_) {
    if (imposed.count(h.node)) continue;  // the tip holds it
    const Vec3 offset = frame * h.offset_blade;
    const double s = (bvh.position(h.node) - offset - edge.tip).dot(e);
    if (s < 0 || s > length) continue;  // the blade slid past it
    const Vec3 held = edge.tip + s * e + offset;
    if ((held - h.touch_point).dot(h.touch_normal) >= 0) continue;  // lifted above the touch
    imposed[h.node] = held - mesh.nodes[h.node];
    kept.push_back(h);
  }
  held_ = std::move(kept);

  // New captures: only between two poses (the line must pass the node).
  if (!previous || length <= 0) return imposed;
  const double margin = 0.5 * length;
  const Box3 box = [&] {
    Box3 b(edge.tip);
    b.extend(edge.heel);
    b.min().array() -= margin;
    b.max().array() += margin;
    return b;
  }();
  std::unordered_map<int, NodeLocal> local;
  for (int t : bvh.near_segment(edge.tip, edge.heel, margin)) {
    const BoundaryTriangle& tri = bvh.surface().triangles[t];
    const bool skin = bvh.is_operation(t) && !tri.cut;
    const Vec3 &a = bvh.position(tri.nodes[0]), &b = bvh.position(tri.nodes[1]),
               &c = bvh.position(tri.nodes[2]);
    const Vec3 area_normal = 0.5 * (b - a).cross(c - a);
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    for (int v : tri.nodes) {
      NodeLocal& l = local[v];
      l.holdable &= skin;
      l.normal += area_normal;
      l.longest_edge = std::max(l.longest_edge, longest);
    }
  }
  const Eigen::Matrix3d previous_frame = blade_frame(*previous);
  const Vec3 previous_e = previous_frame.col(0);
  const double previous_length = (previous->heel - previous->tip).norm();
  std::vector<EdgeHeldNode> captured;
  for (const auto& [v, l] : local) {
    if (!l.holdable || imposed.count(v) || l.normal.squaredNorm() == 0) continue;
    const Vec3& x = bvh.position(v);
    if (!box.contains(x)) continue;  // its triangles may lie partly outside the candidates
    const Vec3 n = l.normal.normalized();
    if (std::abs(e.dot(n)) > options_.max_edge_slope) continue;
    // Depth is measured in the blade's plane, across the edge (where the node will be held):
    // `out` is the blade's in-plane perpendicular on the skin's side. A blade lying on its
    // flat (its plane near the tangent plane) has no edge pointing into the skin.
    const Vec3 out = frame.col(2).dot(n) >= 0 ? Vec3(frame.col(2)) : Vec3(-frame.col(2));
    if (out.dot(n) < options_.min_plane_alignment) continue;
    const double s = (x - edge.tip).dot(e);
    if (s < 0 || s > length) continue;
    const Vec3 r = x - (edge.tip + s * e);  // from the line to the node, across the edge
    // The line passed the node: at or above it before, below it now; or the blade, already
    // below, has slid along its length under the node (it was past its end before).
    const Vec3 previous_out = previous_frame.col(2).dot(n) >= 0 ? Vec3(previous_frame.col(2))
                                                                : Vec3(-previous_frame.col(2));
    const double s_previous = (x - previous->tip).dot(previous_e);
    const Vec3 r_previous = x - (previous->tip + s_previous * previous_e);
    const bool was_beside = s_previous >= 0 && s_previous <= previous_length;
    // A node the blade's end slides under must be near the line already (the dimple's
    // slope), not a node far above it that the end merely came level with.
    const bool slid_under = !was_beside && r.dot(out) <= options_.max_entry_depth * l.longest_edge;
    if (!(r.dot(out) > 0 && (r_previous.dot(previous_out) <= 0 || slid_under))) continue;
    // Sideways = along the blade's normal (the blade is a plate in its x-z plane): the held
    // node keeps that offset and takes the line's place in the blade's plane.
    const double lateral = r.dot(frame.col(1));
    if (std::abs(lateral) > options_.lateral_reach * l.longest_edge) continue;
    EdgeHeldNode h;
    h.node = v;
    h.offset_blade = Vec3(0, lateral, 0);
    h.touch_point = x;
    h.touch_normal = out;
    imposed[v] = edge.tip + s * e + frame * h.offset_blade - mesh.nodes[v];
    captured.push_back(h);
  }
  held_.insert(held_.end(), captured.begin(), captured.end());
  std::sort(held_.begin(), held_.end(),
            [](const EdgeHeldNode& a, const EdgeHeldNode& b) { return a.node < b.node; });
  return imposed;
}

void EdgeContact::release() {
  held_.clear();
  tip_anchor_.reset();
}

BladeWrench blade_wrench(const Vec3& tip, const std::vector<Vec3>& held_position,
                         const std::vector<Vec3>& holding_force) {
  BladeWrench w;
  for (size_t k = 0; k < held_position.size() && k < holding_force.size(); ++k) {
    const Vec3 on_blade = -holding_force[k];
    w.force += on_blade;
    w.torque += (held_position[k] - tip).cross(on_blade);
  }
  return w;
}

BladeWrench in_blade_frame(const BladeWrench& w, const BladeEdge& edge) {
  const Eigen::Matrix3d frame = blade_frame(edge);
  return BladeWrench{frame.transpose() * w.force, frame.transpose() * w.torque};
}

double sweep_area(const BladeEdge& from, const BladeEdge& to) {
  // The triangles (A0, B0, B1) and (A0, B1, A1), as cut_sweep.hpp splits the bilinear patch.
  return 0.5 * ((from.heel - from.tip).cross(to.heel - from.tip).norm() +
                (to.heel - from.tip).cross(to.tip - from.tip).norm());
}

namespace {

// Distance from p to triangle (a, b, c) (Ericson's closest point, 5.1.5).
double distance_to_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.norm();
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + d1 / (d1 - d3) * ab)).norm();
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + d2 / (d2 - d6) * ac)).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
  const double denom = 1.0 / (va + vb + vc);
  return (p - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

}  // namespace

double swept_before_fraction(const std::vector<BladeEdge>& stroke, const BladeEdge& from,
                             const BladeEdge& to, double tolerance, double below) {
  const std::array<std::array<Vec3, 3>, 2> now = {
      {{from.tip, from.heel, to.heel}, {from.tip, to.heel, to.tip}}};
  const double length = (from.heel - from.tip).norm(), reach = tolerance * length;
  // Only the stroke's triangles within reach of this sweep's box can hold a sample: the
  // others are skipped unmeasured (a slow stroke has thousands, and this runs every step).
  Vec3 lo = from.tip.cwiseMin(from.heel).cwiseMin(to.tip).cwiseMin(to.heel);
  Vec3 hi = from.tip.cwiseMax(from.heel).cwiseMax(to.tip).cwiseMax(to.heel);
  lo.array() -= reach;
  hi.array() += reach;
  std::vector<std::array<Vec3, 3>> before;
  for (size_t k = 1; k < stroke.size(); ++k) {
    const BladeEdge &a = stroke[k - 1], &b = stroke[k];
    for (const std::array<Vec3, 3>& t :
         {std::array<Vec3, 3>{a.tip, a.heel, b.heel}, std::array<Vec3, 3>{a.tip, b.heel, b.tip}}) {
      const Vec3 t_lo = t[0].cwiseMin(t[1]).cwiseMin(t[2]),
                 t_hi = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
      if ((t_lo.array() <= hi.array()).all() && (t_hi.array() >= lo.array()).all())
        before.push_back(t);
    }
  }
  // Interior sample points of each triangle (barycentric grid), weighted by its area.
  constexpr int kGrid = 6;
  constexpr int kSamples = kGrid * (kGrid + 1) / 2;
  std::array<double, 2> area{};
  double total = 0;
  for (size_t k = 0; k < now.size(); ++k) {
    const auto& t = now[k];
    area[k] = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).norm();
    // A triangle narrower than `reach` across the edge (a blade held still, or moved along its
    // own edge: a plunge) sweeps nothing, whatever its last digits: else such a move measured
    // 0 when its area came out exactly 0 and 1 (wholly within reach of the last sweep) when
    // rounding left 1e-17, and a 1e-16 change of the poses freed the blade or not.
    if (area[k] <= 0.5 * reach * length) area[k] = 0;
    total += area[k];
  }
  // Uncovered area past which the fraction is surely under `below`.
  const double too_much = (1 - below) * total * (1 + 1e-9) + 1e-300;
  double uncovered = 0;
  std::array<int, 2> in{};
  for (size_t k = 0; k < now.size(); ++k) {
    if (area[k] == 0) continue;
    const auto& t = now[k];
    for (int i = 0; i < kGrid; ++i)
      for (int j = 0; i + j < kGrid; ++j) {
        const double u = (i + 1.0 / 3) / kGrid, v = (j + 1.0 / 3) / kGrid;
        const Vec3 p = t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]);
        bool hit = false;
        for (const auto& b : before)
          if (distance_to_triangle(p, b[0], b[1], b[2]) <= reach) {
            hit = true;
            break;
          }
        in[k] += hit;
        if (!hit && below > 0 && (uncovered += area[k] / kSamples) > too_much)
          return (total - uncovered) / total;
      }
  }
  double covered = 0;
  for (size_t k = 0; k < now.size(); ++k)
    if (area[k] > 0) covered += area[k] * in[k] / kSamples;
  return total > 0 ? covered / total : 0;
}

}  // namespace stc
