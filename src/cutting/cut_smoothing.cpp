#include "cutting/cut_smoothing.hpp"

#include "cutting/node_moves.hpp"
#include "cutting/tet_flips.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace stc {
namespace {

// A search step must raise the star's smallest angle by more than this (degrees): well above
// round-off, so a step is not decided by the last digits of a position.
constexpr double kStepGainDeg = 1e-4;
// A move is kept only if it raises the star's smallest angle by this much (degrees).
constexpr double kMoveGainDeg = 0.05;

// The smallest dihedral angle of tet t with node v at x.
double tet_smallest_dihedral(const TetMesh& mesh, int t, int v, const Vec3& x) {
  const Tet& k = mesh.tets[t];
  const Vec3* p[4];
  for (int i = 0; i < 4; ++i) p[i] = k[i] == v ? &x : &mesh.nodes[k[i]];
  return smallest_dihedral_deg(*p[0], *p[1], *p[2], *p[3]);
}

// The volume of v's star with v at x.
double star_volume(const TetMesh& mesh, const CutState& state, int v, const Vec3& x) {
  double volume = 0;
  for (int t : state.node_tets[v]) {
    const Tet& k = mesh.tets[t];
    const Vec3* p[4];
    for (int i = 0; i < 4; ++i) p[i] = k[i] == v ? &x : &mesh.nodes[k[i]];
    volume += signed_volume(*p[0], *p[1], *p[2], *p[3]);
  }
  return volume;
}

// The smallest volume ratio (mesh/quality.hpp) of v's star with v at x.
double star_smallest_volume_ratio(const TetMesh& mesh, const CutState& state, int v,
                                  const Vec3& x) {
  double smallest = 1e300;
  for (int t : state.node_tets[v]) {
    const Tet& k = mesh.tets[t];
    const Vec3* p[4];
    for (int i = 0; i < 4; ++i) p[i] = k[i] == v ? &x : &mesh.nodes[k[i]];
    smallest = std::min(smallest, volume_ratio(*p[0], *p[1], *p[2], *p[3]));
  }
  return smallest;
}

// The tet of v's star with the smallest dihedral angle, v at x.
int worst_tet(const TetMesh& mesh, const CutState& state, int v, const Vec3& x) {
  int worst = -1;
  double worst_angle = 1e300;
  for (int t : state.node_tets[v]) {
    const double a = tet_smallest_dihedral(mesh, t, v, x);
    if (a < worst_angle) worst_angle = a, worst = t;
  }
  return worst;
}

// Eq. (20b): maximise q(x) = the smallest dihedral angle of v's star over v's position x by an
// ascent on the worst tet's smallest angle (its gradient by central differences) with a step
// that grows on success and halves on failure; q is non-smooth where two tets tie, which the
// step's acceptance test (q itself, not the worst tet's angle) handles. Returns the best x.
// A boundary node's moves are projected onto its fan's plane or its crease's line (how, axis:
// how_node_may_move's).
Vec3 best_position(const TetMesh& mesh, const CutState& state, int v, double guard, NodeMove how,
                   const Vec3& axis, double& quality) {
  const auto allowed = [how, &axis](const Vec3& d) -> Vec3 {
    if (how == NodeMove::kInPlane) return d - axis * axis.dot(d);
    if (how == NodeMove::kOnLine) return axis * axis.dot(d);
    return d;
  };
  const Vec3 start = mesh.nodes[v];
  double shortest = 1e300;
  Vec3 centroid = Vec3::Zero();
  int neighbours = 0;
  for (int t : state.node_tets[v])
    for (int w : mesh.tets[t])
      if (w != v) {
        shortest = std::min(shortest, (mesh.nodes[w] - start).norm());
        centroid += mesh.nodes[w];
        ++neighbours;
      }
  Vec3 x = start;
  double q = star_smallest_dihedral(mesh, state, v, x, guard);
  // No tet of the star may end up flatter by the other measure than the star's worst now.
  const double ratio_floor = star_smallest_volume_ratio(mesh, state, v, start);
  const auto better = [&](const Vec3& y, double qy) {
    return qy > q + kStepGainDeg && star_smallest_volume_ratio(mesh, state, v, y) >= ratio_floor;
  };
  // The centroid of the star's other corners (Laplacian smoothing) as a first guess.
  if (neighbours > 0) {
    const Vec3 c = start + allowed(centroid / neighbours - start);
    const double qc = star_smallest_dihedral(mesh, state, v, c, guard);
    if (better(c, qc)) x = c, q = qc;
  }
  double step = 0.1 * shortest;
  const double eps = 1e-4 * shortest, smallest_step = 1e-2 * shortest;
  // The ascent direction at x: the worst tet's gradient within the plane or line (zero: none). A
  // gradient (nearly) normal to the plane is none: what the projection leaves of it is
  // round-off, and normalising that would step off the plane.
  const auto direction = [&](const Vec3& at) -> Vec3 {
    const int worst = worst_tet(mesh, state, v, at);
    Vec3 gradient;
    for (int i = 0; i < 3; ++i) {
      Vec3 up = at, down = at;
      up[i] += eps;
      down[i] -= eps;
      gradient[i] = (tet_smallest_dihedral(mesh, worst, v, up) -
                     tet_smallest_dihedral(mesh, worst, v, down)) /
                    (2 * eps);
    }
    const Vec3 along = allowed(gradient);
    return along.norm() > 1e-6 * gradient.norm() ? Vec3(along.normalized()) : Vec3::Zero();
  };
  Vec3 along = direction(x);
  for (int iteration = 0; iteration < 30 && step > smallest_step && along != Vec3::Zero();
       ++iteration) {
    const Vec3 y = x + allowed(step * along);
    const double qy = star_smallest_dihedral(mesh, state, v, y, guard);
    if (better(y, qy)) {
      x = y, q = qy;
      along = direction(x);
      step = std::min(1.5 * step, 0.5 * shortest);
    } else {
      step *= 0.5;  // the same direction, a shorter step
    }
  }
  quality = q;
  return x;
}

// Smooths the nodes of `tets` (those below the threshold) that may move.
void smooth_tets(TetMesh& mesh, CutState& state, const CutOptions& options,
                 const std::vector<int>& tets, CutResult& result) {
  if (!(options.smooth_below_deg > 0)) return;
  const double guard = 2 * options.min_volume_fraction;
  std::vector<int> changed = tets;
  for (int pass = 0; pass < 2; ++pass) {
    // The candidates in ascending order: the result does not depend on the tets' order. The
    // second pass looks at the tets the first one changed.
    const size_t changed_before = result.changed_tets.size();
    std::set<int> nodes;
    for (int t : changed) {
      const Tet& k = mesh.tets[t];
      if (smallest_dihedral_deg(mesh.nodes[k[0]], mesh.nodes[k[1]], mesh.nodes[k[2]],
                                mesh.nodes[k[3]]) >= options.smooth_below_deg)
        continue;
      for (int v : k) nodes.insert(v);
    }
    bool moved = false;
    for (int v : nodes) {
      Vec3 axis = Vec3::Zero();
      const NodeMove how = how_node_may_move(mesh, state, v, axis);
      if (how == NodeMove::kNone) continue;
      const double before = star_smallest_dihedral(mesh, state, v, mesh.nodes[v], -1e300);
      double after = before;
      const Vec3 x = best_position(mesh, state, v, guard, how, axis, after);
      if (!(after > before + kMoveGainDeg)) continue;
      // The star's volume is affine in x_v with a gradient normal to the fan's plane, or to the
      // crease's line (zero inside): a move that changes it beyond round-off is refused
      // (docs/SCENE.md "Cut invariants" 2).
      const double volume = star_volume(mesh, state, v, mesh.nodes[v]);
      if (std::abs(star_volume(mesh, state, v, x) - volume) > 1e-12 * volume) continue;
      move_node(mesh, state, v, x, result);
      moved = true;
    }
    if (!moved) break;
    changed.assign(result.changed_tets.begin() + static_cast<std::ptrdiff_t>(changed_before),
                   result.changed_tets.end());
  }
}

}  // namespace

void smooth_last_stroke(TetMesh& mesh, CutState& state, const CutOptions& options,
                        CutResult& result) {
  std::vector<int> tets = std::move(state.stroke_tets);
  state.stroke_tets.clear();
  std::sort(tets.begin(), tets.end());
  tets.erase(std::unique(tets.begin(), tets.end()), tets.end());
  smooth_tets(mesh, state, options, tets, result);
  // What smoothing could not raise (corners that may not move: on the curved skin, on several
  // cut planes, locked), flips may (docs/DESIGN.md section 8, "Flip"): the stroke's tets and
  // those the smoothing changed, as they are now.
  if (options.flip_thin_tets) {
    tets.insert(tets.end(), result.changed_tets.begin(), result.changed_tets.end());
    result.flips += flip_thin_tets(mesh, state, options, tets, result).total();
  }
}

}  // namespace stc
