#include "cutting/triangle_cut.hpp"

#include "cutting/edge_bisection.hpp"
#include "cutting/node_moves.hpp"
#include "soft_tissue_cutting/collision/blade.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace stc {
namespace {

// Face f of tet t, and its side in the tet across it, marked on the cut (both tets get its bit).
void mark_cut_face(TetMesh& mesh, int t, int f, int other, int other_face,
                   std::set<FaceKey>& new_faces) {
  mesh.cut_faces[t] |= static_cast<std::uint8_t>(1u << f);
  mesh.cut_faces[other] |= static_cast<std::uint8_t>(1u << other_face);
  new_faces.insert(face_key(mesh.tets[static_cast<size_t>(t)], f));
}

// Would opening face f of tet t leave t with two faces on the tissue's surface - f and one
// already on its boundary (skin, an opened wall) or marked - meeting at under `limit` degrees
// at their common edge (CutOptions::wedge_min_deg)? Such a tet is a flap of tissue no later
// repair can thicken: every tet around that edge shares its angle (docs/DESIGN.md section 8,
// "Where bisection stops" (d)). It stays joined across f instead; the cut then runs along its
// other face, within the flap's thickness of the blade.
bool leaves_wedge(const TetMesh& mesh, const CutState& state, int t, int f, double limit) {
  if (!(limit > 0)) return false;
  const Tet& k = mesh.tets[static_cast<size_t>(t)];
  // Angle i is between faces (0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3) (quality.cpp).
  const std::array<double, 6> angles =
      dihedral_angles_deg(mesh.nodes[k[0]], mesh.nodes[k[1]], mesh.nodes[k[2]], mesh.nodes[k[3]]);
  constexpr int kPair[4][4] = {{-1, 0, 1, 2}, {0, -1, 3, 4}, {1, 3, -1, 5}, {2, 4, 5, -1}};
  for (int g = 0; g < 4; ++g) {
    if (g == f || !(angles[static_cast<size_t>(kPair[f][g])] < limit)) continue;
    if (mesh.is_cut_face(t, g) || neighbour_across(mesh, state, t, g).first < 0) return true;
  }
  return false;
}

// A crossing this near an end of its edge (a fraction of the edge) puts that end on the cut
// as it is: it is not moved there.
constexpr double kNegligibleMove = 1e-3;

// Is the stroke's surface flat where it meets the box [lo, hi]: every triangle of it there
// within 10 deg of `normal`? (A straight stroke's is; a curved, tilted one's turns.)
bool flat_within(const std::vector<std::array<Vec3, 3>>& surface, const Vec3& normal,
                 const Vec3& lo, const Vec3& hi) {
  const double cos_limit = std::cos(10.0 * M_PI / 180.0);
  for (const auto& s : surface) {
    const Vec3 a = s[0].cwiseMin(s[1]).cwiseMin(s[2]), b = s[0].cwiseMax(s[1]).cwiseMax(s[2]);
    if ((b.array() < lo.array()).any() || (a.array() > hi.array()).any()) continue;
    const Vec3 n = (s[1] - s[0]).cross(s[2] - s[0]);
    if (!(n.squaredNorm() > 0)) continue;
    if (std::abs(n.normalized().dot(normal)) < cos_limit) return false;
  }
  return true;
}

// Is node v on the mesh's boundary (a face of one of its tets with no neighbour)?
bool on_boundary(const TetMesh& mesh, const CutState& state, int v) {
  const std::vector<std::array<int, 4>> across = star_neighbours(mesh, state, v);
  for (size_t k = 0; k < across.size(); ++k)
    for (int f = 0; f < 4; ++f)
      if (mesh.tets[state.node_tets[v][k]][f] != v && across[k][f] < 0) return true;
  return false;
}

// Where a point meets a border segment's line or ends, as a fraction of the segment's length:
// well above round-off, so a blade placed exactly on the mesh's nodes or grid lines (a
// structured mesh, a scripted path) is not decided by noise - the same cut whatever the
// solver's last digits.
constexpr double kOnBorderSlack = 1e-6;

// A crossing of the tip's path (CutOptions::tip_border_on_path) lies on it up to this fraction
// of its edge's length: the distance past a polyline is linear along an edge only while one
// segment of it is the nearest.
constexpr double kOnPathFraction = 0.05;

// How far x lies past the polyline `line` (along `past`, the way beyond it, interpolated at its
// nearest point; < 0 short of it), `fallback` where that way is 0. `inside`, if given: whether the
// nearest point lies within the line (not beyond either end).
double past_polyline(const std::vector<Vec3>& line, const std::vector<Vec3>& past, const Vec3& x,
                     double fallback, bool* inside) {
  double nearest = std::numeric_limits<double>::infinity(), beyond = fallback;
  if (inside) *inside = false;
  for (size_t i = 0; i < line.size(); ++i) {
    // Segment i (a single point where the line has one).
    const size_t j = std::min(i + 1, line.size() - 1);
    if (j == i && line.size() > 1) break;
    const Vec3 d = line[j] - line[i];
    const double raw = d.squaredNorm() > 0 ? (x - line[i]).dot(d) / d.squaredNorm() : 0.0;
    const double u = std::clamp(raw, 0.0, 1.0);
    const Vec3 at = line[i] + u * d;
    const double distance = (x - at).norm();
    if (distance >= nearest) continue;
    nearest = distance;
    const Vec3 way = (1 - u) * past[i] + u * past[j];
    beyond = way.norm() > 0 ? (x - at).dot(way.normalized()) : fallback;
    if (inside) *inside = j > i && !(i == 0 && raw < 0) && !(j + 1 == line.size() && raw > 1);
  }
  return beyond;
}

// The six edges of a tet as local vertex pairs.
constexpr int kTetEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

struct Split {
  int a, b;  // a < b
  double t;  // crossing at x_a + t (x_b - x_a)
};

// A piece of a tet being bisected: its corners (negative ids: crossing points not made yet).
struct Piece {
  std::array<int, 4> id;
  std::array<Vec3, 4> x;
};

// The pieces tet `nodes` falls into when the crossing edges in `splits` are bisected in that
// order (the order split_along_triangle applies them in). Each piece containing an edge being
// split is bisected, exactly as bisect_edge does.
std::vector<Piece> pieces_of(const TetMesh& mesh, const Tet& nodes,
                             const std::vector<Split>& splits) {
  std::vector<Piece> pieces(1);
  for (int k = 0; k < 4; ++k) {
    pieces[0].id[k] = nodes[k];
    pieces[0].x[k] = mesh.nodes[nodes[k]];
  }
  int next_virtual = -1;
  for (const Split& s : splits) {
    const Vec3 m = mesh.nodes[s.a] + s.t * (mesh.nodes[s.b] - mesh.nodes[s.a]);
    const int mid = next_virtual--;
    const size_t count = pieces.size();
    for (size_t p = 0; p < count; ++p) {
      auto ia = std::find(pieces[p].id.begin(), pieces[p].id.end(), s.a) - pieces[p].id.begin();
      auto ib = std::find(pieces[p].id.begin(), pieces[p].id.end(), s.b) - pieces[p].id.begin();
      if (ia == 4 || ib == 4) continue;
      Piece other = pieces[p];
      pieces[p].id[ib] = mid;
      pieces[p].x[ib] = m;
      other.id[ia] = mid;
      other.x[ia] = m;
      pieces.push_back(other);
    }
  }
  return pieces;
}

// The crossings of `crossing` on tet `nodes`' edges, ordered by edge (the order
// split_along_triangle bisects them in).
std::vector<Split> splits_of(const Tet& nodes,
                             const std::map<std::pair<int, int>, double>& crossing) {
  std::vector<Split> splits;
  for (const auto& e : kTetEdges) {
    const int u = std::min(nodes[e[0]], nodes[e[1]]), v = std::max(nodes[e[0]], nodes[e[1]]);
    auto it = crossing.find({u, v});
    if (it != crossing.end()) splits.push_back({u, v, it->second});
  }
  std::sort(splits.begin(), splits.end(), [](const Split& x, const Split& y) {
    return std::make_pair(x.a, x.b) < std::make_pair(y.a, y.b);
  });
  return splits;
}

// The guards on a split: would bisecting `splits` leave a piece of tet t under
// min_volume_fraction of the tet it descends from (the volume guard), or - with the shape guard
// on (CutOptions::split_min_dihedral_deg, docs/DESIGN.md section 8 "Shape guard", eq. (20c)) - a
// piece whose smallest dihedral angle is under the limit, or under the tet's own where that is
// less (a thin tet may still be cut, never into something thinner than itself)?
bool too_thin(const TetMesh& mesh, const CutState& state, int t, const std::vector<Split>& splits,
              const CutOptions& options) {
  const Tet& nodes = mesh.tets[t];
  const std::vector<Piece> pieces = pieces_of(mesh, nodes, splits);
  double smallest = 1e300;
  for (const Piece& p : pieces)
    smallest = std::min(smallest, signed_volume(p.x[0], p.x[1], p.x[2], p.x[3]));
  if (!(smallest >= options.min_volume_fraction * state.origin_volume[t])) return true;
  if (!(options.split_min_dihedral_deg > 0)) return false;
  double thinnest = 180;
  for (const Piece& p : pieces)
    thinnest = std::min(thinnest, smallest_dihedral_deg(p.x[0], p.x[1], p.x[2], p.x[3]));
  if (thinnest >= options.split_min_dihedral_deg - kAngleRoundOffDeg) return false;
  // Only now the tet's own angle (most splits pass above without it).
  const double own = smallest_dihedral_deg(mesh.nodes[nodes[0]], mesh.nodes[nodes[1]],
                                           mesh.nodes[nodes[2]], mesh.nodes[nodes[3]]);
  return thinnest < std::min(options.split_min_dihedral_deg, own) - kAngleRoundOffDeg;
}

// A crossing moved along its edge (Shift::edge, a < b) to parameter `to`; edge.first < 0: none.
struct Shift {
  std::pair<int, int> edge{-1, -1};
  double to = 0;
};

// Steps of the search for a guard-passing crossing along an edge (CutOptions::split_shift,
// border_shift are its range).
constexpr int kShiftSteps = 10;

// The nearest t' = t -+ k range / kShiftSteps (k = 1, 2, ..., kShiftSteps; t - first) in
// [snap, 1 - snap] where fits(t'), the search ending at the first k whose offset is not
// within(offset); NaN if none (docs/DESIGN.md section 8 "Shape guard", eq. (20d)). `offset`
// gets the k range / kShiftSteps found.
template <class Within, class Fits>
double nearest_passing(double t, double range, double snap, Within within, Fits fits,
                       double& offset) {
  for (int i = 1; i <= kShiftSteps; ++i) {
    const double by = i * range / kShiftSteps;
    if (!within(by)) break;
    for (const double to : {t - by, t + by})
      if (to >= snap && to <= 1 - snap && fits(to)) return offset = by, to;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// The move of one of `splits`' crossings (those of a tet the guards refuse) along its edge
// (nearest_passing, up to split_shift) after which every tet on that edge passes the guards
// with its other crossings as they are: the one that leaves its new node nearest the
// triangle's plane, if nearer than `limit` (where the end snapped instead lies). An edge
// already moved (`shifted`) is not moved again, so the rounds of split_along_triangle end.
Shift nearest_shift(const TetMesh& mesh, const CutState& state, const TriangleClassification& tri,
                    const std::vector<Split>& splits,
                    const std::map<std::pair<int, int>, double>& crossing,
                    const std::map<std::pair<int, int>, double>& shifted, double limit,
                    const CutOptions& options) {
  Shift best;
  if (!(options.split_shift > 0)) return best;
  for (const Split& sp : splits) {
    if (shifted.count({sp.a, sp.b})) continue;
    // How far off the plane the new node moves per unit of t.
    const double rate = std::abs(tri.distance(mesh, sp.a) - tri.distance(mesh, sp.b));
    const std::vector<int> around = tets_with_edge(state, sp.a, sp.b);
    auto fits = [&](double to) {
      for (int k : around) {
        std::vector<Split> moved = splits_of(mesh.tets[k], crossing);
        for (Split& x : moved)
          if (x.a == sp.a && x.b == sp.b) x.t = to;
        if (too_thin(mesh, state, k, moved, options)) return false;
      }
      return true;
    };
    double by = 0;
    const double to = nearest_passing(
        sp.t, options.split_shift, options.snap_tolerance,
        [&](double offset) { return offset * rate < limit; }, fits, by);
    if (!std::isnan(to)) limit = by * rate, best = {{sp.a, sp.b}, to};
  }
  return best;
}

// Node v is on triangle `tri`'s cut now: snapped in place (moved false) or moved exactly onto
// its plane. A node moved there beyond the triangle (`outside`: an edge of a tet the whole plane
// cuts) is on the surface's extension for the stroke's later triangles (cut_state.hpp); any
// other is on the stroke.
void take_onto_cut(TriangleClassification& tri, CutState& state, int v, bool moved, bool outside) {
  tri.set_on(v);
  if (!outside || !moved)
    set_on_stroke(state, v);
  else
    set_on_extension(state, v);
}

// Moves node v to `target` if v is an interior, unlocked node of the operation part that no
// marked face touches, and its star keeps positive volume above the size guard and a smallest
// dihedral angle no worse than min(limit, the star's current one). Returns whether it moved.
bool relocate_node(TetMesh& mesh, CutState& state, int v, const Vec3& target,
                   const CutOptions& options, CutResult& result) {
  if (!may_move_inside_star(mesh, state, v)) return false;
  const double before = star_smallest_dihedral(mesh, state, v, mesh.nodes[v], -1e300);
  const double after =
      star_smallest_dihedral(mesh, state, v, target, 2 * options.min_volume_fraction);
  // "No worse" up to round-off (kAngleRoundOffDeg); -1 (a tet under the guard) always fails.
  if (after < std::min(before, options.relocate_min_dihedral_deg) - kAngleRoundOffDeg) return false;
  move_node(mesh, state, v, target, result);
  return true;
}

}  // namespace

StrokeSurface::StrokeSurface(const std::vector<std::array<Vec3, 3>>& triangles)
    : triangles_(triangles) {
  for (const auto& s : triangles_) {
    lo_.push_back(s[0].cwiseMin(s[1]).cwiseMin(s[2]));
    hi_.push_back(s[0].cwiseMax(s[1]).cwiseMax(s[2]));
  }
}

double StrokeSurface::first_within(const Vec3& x, double slack) const {
  for (size_t i = 0; i < triangles_.size(); ++i) {
    if ((x.array() < lo_[i].array() - slack).any() || (x.array() > hi_[i].array() + slack).any())
      continue;
    const auto& s = triangles_[i];
    Vec3 w;
    const double distance = (closest_point_on_triangle(x, s[0], s[1], s[2], w) - x).norm();
    if (distance <= slack) return distance;
  }
  return -1;
}

bool StrokeSurface::near_node(const TetMesh& mesh, int v, double slack) {
  auto [it, fresh] = known_.try_emplace(v, Known{});
  Known& known = it->second;
  if (slack >= known.near_at) return true;
  if (slack <= known.far_below) return false;
  if (const double distance = first_within(mesh.nodes[v], slack); distance >= 0) {
    known.near_at = std::min(known.near_at, distance);
    return true;
  }
  known.far_below = std::max(known.far_below, slack);
  return false;
}

void StrokeSurface::add_limit(std::vector<Vec3> line, std::vector<Vec3> past, double reach,
                              double slack_fraction) {
  if (line.empty() || past.size() != line.size() || limits_.size() == kMaxLimits) return;
  limits_.push_back({std::move(line), std::move(past), reach, slack_fraction});
}

double StrokeSurface::Limit::past_of(const Vec3& x) const {
  return past_polyline(line, past, x, -1, nullptr);
}

bool StrokeSurface::corner_near(const TetMesh& mesh, const CutState& state, int v, double slack,
                                double skin_slack, bool with_limits) {
  if (!near_node(mesh, v, slack)) {
    if (!near_node(mesh, v, skin_slack * slack)) return false;
    std::int8_t& boundary = known_[v].on_boundary;
    if (boundary < 0) boundary = on_boundary(mesh, state, v) ? 1 : 0;
    if (!boundary) return false;
  }
  if (!with_limits) return true;
  for (size_t k = 0; k < limits_.size(); ++k) {
    // Once per node, as the rest (the mesh does not change while faces are marked).
    double& past = known_[v].past[k];
    if (std::isnan(past)) past = limits_[k].past_of(mesh.nodes[v]);
    if (past > limits_[k].reach + limits_[k].slack_fraction * slack) return false;
  }
  return true;
}

bool split_too_thin(const TetMesh& mesh, const CutState& state, int t, int a, int b, double s,
                    const CutOptions& options) {
  return a < b ? too_thin(mesh, state, t, {Split{a, b, s}}, options)
               : too_thin(mesh, state, t, {Split{b, a, 1 - s}}, options);
}

std::vector<int> cuttable_tets_in(const TetMesh& mesh, const CutState& state, const Vec3& lo,
                                  const Vec3& hi) {
  std::vector<int> tets;
  if (!(lo.array() <= hi.array()).all()) return tets;
  for (int t : state.grid.query(mesh, lo, hi))
    if (state.cuttable[t]) tets.push_back(t);
  return tets;
}

double NodeScales::longest_edge(const TetMesh& mesh, const CutState& state, int v) {
  if (longest_.size() < mesh.nodes.size()) longest_.resize(mesh.nodes.size(), -1.0);
  double& longest = longest_[static_cast<size_t>(v)];
  if (longest < 0) longest = star_longest_edge(mesh, state, v);
  return longest;
}

TriangleClassification::TriangleClassification(const Vec3& a, const Vec3& b, const Vec3& c,
                                               double snap_tolerance)
    : a_(a), b_(b), c_(c), normal_((b - a).cross(c - a)), snap_tolerance_(snap_tolerance) {
  double_area_ = normal_.norm();
  const double diameter = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
  degenerate_ = !(double_area_ > 1e-12 * diameter * diameter);  // a plunge sweeps no area
  if (!degenerate_) normal_ /= double_area_;
}

bool TriangleClassification::contains(const Vec3& p, double tol) const {
  const Vec3 q = p - normal_ * normal_.dot(p - a_);
  const double u = normal_.dot((b_ - q).cross(c_ - q)) / double_area_;
  const double v = normal_.dot((c_ - q).cross(a_ - q)) / double_area_;
  return u >= -tol && v >= -tol && 1.0 - u - v >= -tol;
}

int TriangleClassification::side(const TetMesh& mesh, const CutState& state, int v) {
  if (!side_.empty()) {
    auto it = side_.find(v);
    if (it != side_.end()) return it->second;
  }
  const double d = distance(mesh, v);
  // Only nodes on the plane up to round-off start as "on"; split_along_triangle snaps the
  // end of any crossing edge that the plane meets too near it (CutOptions::snap_tolerance).
  const double longest =
      scales_ ? scales_->longest_edge(mesh, state, v) : star_longest_edge(mesh, state, v);
  // A node already on the stroke's cut surface (cut_state.hpp) is on this triangle too when
  // it lies as near its plane as the snap rule lets a cut lie off the blade. Farther off (a
  // curved or twisting stroke: the stroke's earlier triangles are not coplanar with this one)
  // it is classified like any node, so the edges it ends are still split where they cross.
  const double on = is_on_stroke(state, v) ? snap_tolerance_ : 1e-9;
  const int s = std::abs(d) <= on * longest ? 0 : (d > 0 ? 1 : -1);
  // Kept while the mesh changes (a split must not reclassify the ends of the edges it
  // shortened); with shared scales nothing changes any more, and the answer is recomputed
  // from them as cheaply as it would be looked up.
  if (!scales_) side_[v] = s;
  return s;
}

void TriangleClassification::bounds(Vec3& lo, Vec3& hi) const {
  const double diameter = std::max({(b_ - a_).norm(), (c_ - b_).norm(), (a_ - c_).norm()});
  const Vec3 pad = Vec3::Constant(1e-6 * diameter);
  lo = a_.cwiseMin(b_).cwiseMin(c_) - pad;
  hi = a_.cwiseMax(b_).cwiseMax(c_) + pad;
}

std::pair<int, int> neighbour_across(const TetMesh& mesh, const CutState& state, int tet,
                                     int face) {
  const Tet& t = mesh.tets[tet];
  const int p = t[kTetFaces[face][0]], q = t[kTetFaces[face][1]], r = t[kTetFaces[face][2]];
  for (int other : state.node_tets[p]) {
    if (other == tet) continue;
    const Tet& o = mesh.tets[other];
    int fourth = -1, hits = 0;
    for (int k = 0; k < 4; ++k) {
      if (o[k] == p || o[k] == q || o[k] == r)
        ++hits;
      else
        fourth = k;
    }
    if (hits == 3) return {other, fourth};
  }
  return {-1, -1};
}

void split_along_triangle(TetMesh& mesh, CutState& state, TriangleClassification& tri,
                          const CutOptions& options, CutResult& result,
                          const std::vector<int>& whole) {
  if (tri.degenerate()) return;
  // Every tet with a crossing edge inside the triangle overlaps its box.
  Vec3 lo, hi;
  tri.bounds(lo, hi);
  std::vector<int> candidates = cuttable_tets_in(mesh, state, lo, hi);
  if (!whole.empty()) {
    // Their edges may cross the plane outside the triangle's box, so every tet around them
    // (all of which a bisection of such an edge splits) is a candidate, for the volume guard.
    for (int t : whole)
      for (int v : mesh.tets[t])
        for (int k : state.node_tets[v])
          if (state.cuttable[k]) candidates.push_back(k);
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  }

  // (b) Crossing edges inside the triangle. The volume guard may snap an end to "on", which
  // only removes crossing edges, so the loop ends.
  std::map<std::pair<int, int>, double> crossing;
  std::set<std::pair<int, int>> beyond;  // crossing outside the triangle (`whole` tets)
  // Crossings the guards refused where they are, moved along their edges (CutOptions::
  // split_shift): the offset from where the plane crosses, kept across the rounds below.
  std::map<std::pair<int, int>, double> shifted;
  for (;;) {
    crossing.clear();
    beyond.clear();
    bool resnap = false;
    for (int t : candidates) {
      const Tet& tet = mesh.tets[t];
      for (const auto& e : kTetEdges) {
        int u = tet[e[0]], v = tet[e[1]];
        if (tri.side(mesh, state, u) * tri.side(mesh, state, v) != -1) continue;
        if (u > v) std::swap(u, v);
        if (crossing.count({u, v})) continue;
        if (state.locked[u] && state.locked[v]) continue;  // interface edges stay whole
        const double du = tri.distance(mesh, u), dv = tri.distance(mesh, v);
        const double s = du / (du - dv);
        // Outside the triangle (an edge of a `whole` tet): its node is on this triangle's
        // plane but not on the stroke's cut surface, which ends at the border.
        const bool outside = !tri.contains(mesh.nodes[u] + s * (mesh.nodes[v] - mesh.nodes[u]),
                                           options.inside_tolerance);
        if (outside && !std::binary_search(whole.begin(), whole.end(), t)) continue;
        // moved: relocated exactly onto the plane. A node beyond the triangle taken there is on
        // the surface's extension for the stroke's later triangles (cut_state.hpp). One snapped
        // in place (up to the snap distance off the plane) is on the stroke as any snapped node:
        // otherwise it is "on" for this triangle alone, and a face it shares with nodes inside
        // the border - one straddling a tilted stroke's start, refused while the blade was short
        // of its other corners - is never found again (a 3.7 mm hole at the thigh's start). How
        // far past the border such a face may reach is the corner tests' to say (corner_near).
        auto put_on = [&](int node, bool moved) {
          take_onto_cut(tri, state, node, moved, outside);
        };
        // Too near an end: that end is on the cut (snapped, never moved), so every edge that
        // is split has t in [snap, 1 - snap].
        // Near an end: move that end onto the cut if it may move (relocate_node) - unless it
        // is on it but for round-off (moving it would only trade planes with a neighbouring
        // triangle of the stroke, again at every pass).
        if ((s < options.relocate || s > 1 - options.relocate) &&
            std::min(s, 1 - s) > kNegligibleMove) {
          const int end = s < 0.5 ? u : v;
          if (relocate_node(mesh, state, end, mesh.nodes[u] + s * (mesh.nodes[v] - mesh.nodes[u]),
                            options, result)) {
            put_on(end, true);
            resnap = true;
            continue;
          }
        }
        if (s < options.snap_tolerance || s > 1 - options.snap_tolerance) {
          put_on(s < 0.5 ? u : v, false);
          resnap = true;
          continue;
        }
        const auto moved = shifted.find({u, v});
        crossing[{u, v}] = moved == shifted.end() ? s : s + moved->second;
        if (outside) beyond.insert({u, v});
      }
    }
    if (resnap) continue;
    bool snapped = false;
    for (int t : candidates) {
      const std::vector<Split> splits = splits_of(mesh.tets[t], crossing);
      if (splits.empty() || !too_thin(mesh, state, t, splits, options)) continue;
      // Too small a piece: snap the end nearest the plane among this tet's crossing edges.
      int nearest = -1;
      double best = 2.0;
      bool outside = false;
      Vec3 crossing_at = Vec3::Zero();
      for (const Split& s : splits) {
        const bool beyond_here = beyond.count({s.a, s.b}) > 0;
        const Vec3 at = mesh.nodes[s.a] + s.t * (mesh.nodes[s.b] - mesh.nodes[s.a]);
        if (s.t < best) best = s.t, nearest = s.a, outside = beyond_here, crossing_at = at;
        if (1 - s.t < best) best = 1 - s.t, nearest = s.b, outside = beyond_here, crossing_at = at;
      }
      // Or move one crossing along its edge where that puts its new node nearer the plane
      // than the snapped end lies (docs/DESIGN.md section 8 "Shape guard", eq. (20d)).
      if (const Shift shift = nearest_shift(mesh, state, tri, splits, crossing, shifted,
                                            std::abs(tri.distance(mesh, nearest)), options);
          shift.edge.first >= 0) {
        shifted[shift.edge] = shift.to - crossing[shift.edge];
        crossing[shift.edge] = shift.to;
        snapped = true;  // round again: every tet is checked with the moved crossing
        continue;
      }
      // Or move the end onto the plane where it may (relocate_node): snapped in place it would
      // lie up to half an edge off the blade, and so would the faces that open on it.
      if (options.relocate_refused && std::abs(tri.distance(mesh, nearest)) > 0 &&
          best > kNegligibleMove &&
          (relocate_node(mesh, state, nearest, crossing_at, options, result) ||
           relocate_node(mesh, state, nearest,
                         mesh.nodes[nearest] - tri.distance(mesh, nearest) * tri.normal(), options,
                         result))) {
        take_onto_cut(tri, state, nearest, true, outside);
        snapped = true;
        continue;
      }
      tri.set_on(nearest);
      if (!outside) set_on_stroke(state, nearest);
      snapped = true;
    }
    if (!snapped) break;
  }

  // Bisect in (a, b) order, so each tet is cut into exactly the pieces the guard checked.
  for (const auto& [edge, t] : crossing) {
    const size_t before = result.changed_tets.size();
    const int m = bisect_edge(mesh, state, edge.first, edge.second, t, result.changed_tets);
    result.tets_split += static_cast<int>(result.changed_tets.size() - before) / 2;
    tri.set_on(m);
    if (!beyond.count(edge)) set_on_stroke(state, m);
    result.new_nodes.push_back(NewNode::on_edge(m, edge.first, edge.second, t));
  }
}

void split_along_border(TetMesh& mesh, CutState& state, TriangleClassification& tri, const Vec3& p0,
                        const Vec3& p1, const CutOptions& options, const StrokeSurface& surface,
                        CutResult& result, bool tip_path) {
  if (tri.degenerate()) return;
  const Vec3 along = p1 - p0;
  const double length2 = along.squaredNorm();
  if (!(length2 > 0)) return;
  // In the triangle's plane, perpendicular to the border.
  const Vec3 across = tri.normal().cross(along).normalized();
  const Vec3 pad = Vec3::Constant(1e-6 * std::sqrt(length2));
  auto along_segment = [&](const Vec3& x) {
    const double s = along.dot(x - p0) / length2;
    return s >= -kOnBorderSlack && s <= 1 + kOnBorderSlack;
  };
  // (a) The tets the segment runs through: the points where the plane crosses their edges lie
  // on both sides of the border, and one of them beside the segment.
  std::vector<int> whole;
  const double sweep_side = across.dot(tri.centroid() - p0);
  for (int t : cuttable_tets_in(mesh, state, p0.cwiseMin(p1) - pad, p0.cwiseMax(p1) + pad)) {
    bool inside = false, outside = false, beside = false, on_surface = true;
    const Tet& tet = mesh.tets[t];
    double longest = 0;
    for (const auto& e : kTetEdges)
      longest = std::max(longest, (mesh.nodes[tet[e[0]]] - mesh.nodes[tet[e[1]]]).norm());
    Vec3 tet_lo, tet_hi;
    tet_bounds(mesh, t, tet_lo, tet_hi);
    for (const auto& e : kTetEdges) {
      const int u = tet[e[0]], v = tet[e[1]];
      const int su = tri.side(mesh, state, u), sv = tri.side(mesh, state, v);
      Vec3 x;
      if (su == 0)
        x = mesh.nodes[u];
      else if (sv == 0)
        x = mesh.nodes[v];
      else if (su * sv == -1) {
        const double du = tri.distance(mesh, u), dv = tri.distance(mesh, v);
        x = mesh.nodes[u] + du / (du - dv) * (mesh.nodes[v] - mesh.nodes[u]);
      } else {
        continue;
      }
      // A point on the border's line up to round-off (a node a split put there) is on neither
      // side: its sign would be noise, and decide the tet's cut by it.
      const double d = across.dot(x - p0), on_line = kOnBorderSlack * std::sqrt(length2);
      inside = inside || d < -on_line;
      outside = outside || d > on_line;
      beside = beside || along_segment(x);
      if (d * sweep_side > 0 && on_surface)
        on_surface = surface.near(x, kOnCutSlack * longest) ||
                     flat_within(surface.triangles(), tri.normal(), tet_lo, tet_hi);
    }
    if (inside && outside && beside && on_surface) whole.push_back(t);
  }
  std::sort(whole.begin(), whole.end());
  if (!whole.empty()) split_along_triangle(mesh, state, tri, options, result, whole);
  // (b) The edges on the cut that cross the border.
  // Which side of the border a point lies on, and whether it lies along it: past the tip's path
  // (CutOptions::tip_border_on_path) or across the segment's line in the triangle's plane.
  const bool on_path = tip_path && options.tip_border_on_path && state.tip_path.size() >= 2;
  const std::vector<int> candidates =
      cuttable_tets_in(mesh, state, p0.cwiseMin(p1) - pad, p0.cwiseMax(p1) + pad);
  // The path's last stretch, as far back as twice the candidates' longest edge: their edges'
  // crossings lie there, and a long stroke's whole path (up to kMaxStrokeTriangles points)
  // would be searched for every end of every edge at every band.
  std::vector<Vec3> path, way;
  if (on_path) {
    double reach = 0;
    for (int t : candidates)
      for (const auto& e : kTetEdges)
        reach = std::max(reach,
                         (mesh.nodes[mesh.tets[t][e[0]]] - mesh.nodes[mesh.tets[t][e[1]]]).norm());
    reach = 2 * reach + std::sqrt(length2);
    size_t first = state.tip_path.size() - 1;
    for (double walked = 0; first > 0 && walked <= reach; --first)
      walked += (state.tip_path[first] - state.tip_path[first - 1]).norm();
    path.assign(state.tip_path.begin() + static_cast<long>(first), state.tip_path.end());
    way.assign(state.tip_past.begin() + static_cast<long>(first), state.tip_past.end());
  }
  auto past_border = [&](const Vec3& x, bool* along) {
    if (on_path) return past_polyline(path, way, x, 0.0, along);
    if (along) *along = along_segment(x);
    return across.dot(x - p0);
  };
  // An end on the surface's extension past a border is on it as a node on the stroke is:
  // within the snap distance of this triangle's plane (a curved stroke's earlier triangle, at a
  // slight angle to this one, took it there). Along the tip's path, a node near the plane is
  // taken as on it too (CutOptions::path_border_snap: between a curved stroke's bands it is on
  // neither).
  auto on_cut_or_extension = [&](int v) {
    if (tri.side(mesh, state, v) == 0) return true;
    const bool extension = is_on_extension(state, v);
    if (!tip_path && !extension) return false;  // no rule applies: the star is not measured
    const double d = std::abs(tri.distance(mesh, v));
    const double snap = options.snap_tolerance * star_longest_edge(mesh, state, v);
    return (tip_path && d <= options.path_border_snap * snap) || (extension && d <= snap);
  };
  std::map<std::pair<int, int>, double> crossing;
  for (int t : candidates) {
    const Tet& tet = mesh.tets[t];
    for (const auto& e : kTetEdges) {
      const int u = std::min(tet[e[0]], tet[e[1]]), v = std::max(tet[e[0]], tet[e[1]]);
      if (crossing.count({u, v})) continue;
      if (state.locked[u] && state.locked[v]) continue;
      if (!on_cut_or_extension(u) || !on_cut_or_extension(v)) continue;
      const double du = past_border(mesh.nodes[u], nullptr),
                   dv = past_border(mesh.nodes[v], nullptr);
      // An end on the border's line up to round-off is on the border already (an edge along
      // the line would otherwise "cross" it where its ends' noise signs differ).
      const double edge = (mesh.nodes[v] - mesh.nodes[u]).norm();
      const double on_line = kOnBorderSlack * (on_path ? edge : std::sqrt(length2));
      if (std::abs(du) <= on_line || std::abs(dv) <= on_line || !(du * dv < 0)) continue;
      const double s = du / (du - dv);
      if (std::min(s, 1 - s) <= kNegligibleMove) continue;  // an end is on the border already
      const Vec3 x = mesh.nodes[u] + s * (mesh.nodes[v] - mesh.nodes[u]);
      bool along = false;
      const double off = past_border(x, &along);
      if (!along || (on_path && std::abs(off) > kOnPathFraction * edge)) continue;
      // Near an end: move that end onto the border rather than cut a sliver, as in phase 1
      // (it stays on the cut: x lies on the edge, which lies on the cut). A node moves onto a
      // border once: a later stroke along the same path (a repeated ~cut, its rest position
      // carried through a slightly different deformation) would otherwise move it again by a
      // few micrometres at every pass, a change that never settles.
      const int end = s < 0.5 ? u : v;
      if ((s < options.relocate || s > 1 - options.relocate) && !was_moved_to_border(state, end) &&
          relocate_node(mesh, state, end, x, options, result)) {
        // On the border and on the cut (both ends of the edge are): on the stroke, as the
        // node a split would have put there (otherwise it is "on" only for the triangles whose
        // plane it lies near: on a curved stroke the faces from it stayed closed, a 3.7 mm hole
        // above the 36k liver's curved vertical 0.2 mm stroke's tip moved by (0.5, 0.5) mm, 2.22 x
        // the tolerance).
        set_moved_to_border(state, end);
        set_on_stroke(state, end);
        continue;
      }
      if (s < options.snap_tolerance || s > 1 - options.snap_tolerance) continue;
      crossing[{u, v}] = s;
    }
  }
  // The volume guard: drop the crossing nearest an end in any tet it would thin too much
  // (such a face is left whole: the border then runs along its nearer edge or vertex).
  std::map<std::pair<int, int>, double> refused;
  for (bool dropped = true; dropped && !crossing.empty();) {
    dropped = false;
    for (int t : candidates) {
      const std::vector<Split> splits = splits_of(mesh.tets[t], crossing);
      if (splits.empty() || !too_thin(mesh, state, t, splits, options)) continue;
      const Split* worst = &splits.front();
      for (const Split& x : splits)
        if (std::min(x.t, 1 - x.t) < std::min(worst->t, 1 - worst->t)) worst = &x;
      refused.emplace(std::make_pair(worst->a, worst->b), worst->t);
      crossing.erase({worst->a, worst->b});
      dropped = true;
    }
  }
  // A refused crossing is moved along its edge instead, to the nearest point the guards allow
  // (CutOptions::border_shift): the edge lies on the cut, so its new node does too, and only
  // the border moves - by a fraction of the edge - where dropping it would leave the face
  // across the border whole, a hole up to an element wide along the tip's path.
  if (options.border_shift > 0) crossing.insert(refused.begin(), refused.end());
  // Edges the other tets of the candidates' stars share are split there too (bisect_edge
  // splits every tet on the edge), so each such tet must pass the guard as well.
  for (const auto& entry : crossing) {
    const std::pair<int, int> edge = entry.first;
    double t = entry.second;
    const std::vector<int> around = tets_with_edge(state, edge.first, edge.second);
    auto fits_at = [&](double s) {
      for (int k : around)
        if (too_thin(mesh, state, k, {Split{edge.first, edge.second, s}}, options)) return false;
      return true;
    };
    bool fits = !refused.count(edge) && fits_at(t);
    if (!fits && options.border_shift > 0) {
      double by = 0;
      const double to = nearest_passing(
          t, options.border_shift, options.snap_tolerance, [](double) { return true; }, fits_at,
          by);
      if (!std::isnan(to)) t = to, fits = true;
    }
    if (!fits) continue;
    const size_t before = result.changed_tets.size();
    const int m = bisect_edge(mesh, state, edge.first, edge.second, t, result.changed_tets);
    result.tets_split += static_cast<int>(result.changed_tets.size() - before) / 2;
    tri.set_on(m);
    set_on_stroke(state, m);
    result.new_nodes.push_back(NewNode::on_edge(m, edge.first, edge.second, t));
  }
}

void mark_faces_on_triangle(TetMesh& mesh, const CutState& state, TriangleClassification& tri,
                            const Vec3& lo, const Vec3& hi, const CutOptions& options,
                            StrokeSurface& surface, double skin_slack, CutResult& result,
                            std::set<FaceKey>& new_faces) {
  if (tri.degenerate()) return;
  for (int t : cuttable_tets_in(mesh, state, lo, hi)) {
    // A tet with fewer than three corners on the cut has no face on it: checked once per tet
    // (most tets around the blade), before any face.
    const Tet& tet = mesh.tets[t];
    int corners_on = 0;
    for (int v : tet) corners_on += is_on_stroke(state, v) || tri.side(mesh, state, v) == 0;
    if (corners_on < 3) continue;
    for (int f = 0; f < 4; ++f)
      mark_face_on_triangle(mesh, state, tri, t, f, options, surface, skin_slack, result,
                            new_faces);
  }
}

void mark_face_on_triangle(TetMesh& mesh, const CutState& state, TriangleClassification& tri, int t,
                           int f, const CutOptions& options, StrokeSurface& surface,
                           double skin_slack, CutResult& result, std::set<FaceKey>& new_faces) {
  // (c) Faces on the cut: three "on" nodes, centroid inside the triangle, tets on opposite
  // sides. Both tets get the face's bit.
  if (mesh.is_cut_face(t, f)) return;
  const Tet& tet = mesh.tets[t];
  // Any node on the stroke's cut surface may be a corner: a face in the crease between two
  // non-coplanar triangles of the stroke has corners on each; the checks below keep only
  // faces that lie along this triangle (a node on the stroke is "on" whatever its side).
  auto on = [&](int v) { return is_on_stroke(state, v) || tri.side(mesh, state, v) == 0; };
  const int p = tet[kTetFaces[f][0]], q = tet[kTetFaces[f][1]], r = tet[kTetFaces[f][2]];
  if (!on(p) || !on(q) || !on(r)) return;
  // The geometric tests first: most faces of the stroke's surface lie along another of
  // its triangles, and these reject them before the neighbour is looked up.
  const Vec3 &xp = mesh.nodes[p], &xq = mesh.nodes[q], &xr = mesh.nodes[r];
  const Vec3 centroid = (xp + xq + xr) / 3.0;
  if (!tri.contains(centroid, options.inside_tolerance)) return;
  // Nodes that came onto the cut in other sweeps of the stroke lie on it up to the snap
  // rule: the face must lie along this triangle, near its plane and facing its way.
  const Vec3 n = (xq - xp).cross(xr - xp);
  const double longest = std::max({(xq - xp).norm(), (xr - xq).norm(), (xp - xr).norm()});
  if (std::abs(tri.normal().dot(centroid - mesh.nodes[p]) + tri.distance(mesh, p)) >
      kOnCutSlack * longest)
    return;
  if (!(std::abs(n.normalized().dot(tri.normal())) >= 0.5)) return;
  const auto [other, other_face] = neighbour_across(mesh, state, t, f);
  if (other < 0) return;
  // The two tets must not lie on one side of the cut (a fold of snapped nodes); a fourth
  // vertex that is itself on the cut says nothing (a tet lying flat in the cut: if that cuts
  // it loose, separation keeps it attached, separation.cpp).
  const int here = tri.side(mesh, state, tet[f]);
  const int there = tri.side(mesh, state, mesh.tets[other][other_face]);
  if (here != 0 && there != 0 && here == there) return;
  // Its corners too, on the stroke's surface up to the same slack: the centroid alone
  // would open a face that reaches well past a border of the sweep.
  const double slack = kOnCutSlack * longest;
  // A corner on the tissue's boundary may lie skin_slack times farther: there the cut
  // breaks through the skin, and the blade's edge carried to rest coordinates outside the
  // tissue is extrapolated (rest_mapping.hpp), so the stroke's surface only approximates
  // where the blade crossed the skin.
  auto corner_ok = [&](int v, bool with_limits) {
    return surface.corner_near(mesh, state, v, slack, skin_slack, with_limits);
  };
  if (!corner_ok(p, true) || !corner_ok(q, true) || !corner_ok(r, true)) {
    // Past the blade only: tested again as it moves on (mark_deferred_faces).
    if (surface.limited() && corner_ok(p, false) && corner_ok(q, false) && corner_ok(r, false))
      surface.defer(face_key(tet, f));
    return;
  }
  if (!state.cuttable[other]) {  // the blade stops at the condensed part
    result.reached_interface = true;
    return;
  }
  if (leaves_wedge(mesh, state, t, f, options.wedge_min_deg) ||
      leaves_wedge(mesh, state, other, other_face, options.wedge_min_deg))
    return;
  mark_cut_face(mesh, t, f, other, other_face, new_faces);
}

std::vector<FaceKey> mark_deferred_faces(TetMesh& mesh, const CutState& state,
                                         const std::vector<FaceKey>& faces, StrokeSurface& surface,
                                         double skin_slack, std::set<FaceKey>& new_faces,
                                         double wedge_min_deg) {
  std::vector<FaceKey> still;
  for (const FaceKey& key : faces) {
    if (key[0] < 0 || static_cast<size_t>(key[2]) >= state.node_tets.size()) continue;  // sorted
    // The tet that still has this face (a later split replaced it otherwise), and its side.
    int t = -1, f = -1;
    for (int k : state.node_tets[static_cast<size_t>(key[0])]) {
      for (int g = 0; g < 4 && f < 0; ++g)
        if (face_key(mesh.tets[static_cast<size_t>(k)], g) == key) t = k, f = g;
      if (f >= 0) break;
    }
    if (t < 0 || !state.cuttable[static_cast<size_t>(t)] || mesh.is_cut_face(t, f)) continue;
    const auto [other, other_face] = neighbour_across(mesh, state, t, f);
    if (other < 0 || !state.cuttable[static_cast<size_t>(other)]) continue;
    double longest = 0;
    for (int e = 0; e < 3; ++e)
      longest = std::max(longest, (mesh.nodes[key[e]] - mesh.nodes[key[(e + 1) % 3]]).norm());
    const double slack = kOnCutSlack * longest;
    bool near = true;
    for (int v : key) near = near && surface.corner_near(mesh, state, v, slack, skin_slack);
    if (!near) {
      still.push_back(key);
      continue;
    }
    if (leaves_wedge(mesh, state, t, f, wedge_min_deg) ||
        leaves_wedge(mesh, state, other, other_face, wedge_min_deg))
      continue;
    mark_cut_face(mesh, t, f, other, other_face, new_faces);
  }
  return still;
}

}  // namespace stc
