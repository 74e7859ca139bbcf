#include "cutting/tet_flips.hpp"

#include "cutting/triangle_cut.hpp"
#include "cutting/vertex_insertion.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace stc {
namespace {

// A flip must gain more than this over the tets it replaces (as the smoothing's move must):
// well above round-off, so no flip is decided by a position's last digits.
constexpr double kFlipGainDeg = 0.05;
// Edge removal up to this many tets around the edge (a ring of 7: 42 triangulations, 10 tets).
constexpr int kMaxRing = 7;

double smallest_angle(const TetMesh& mesh, const Tet& k) {
  return smallest_dihedral_deg(mesh.nodes[k[0]], mesh.nodes[k[1]], mesh.nodes[k[2]],
                               mesh.nodes[k[3]]);
}

double volume_of(const TetMesh& mesh, const Tet& k) {
  return signed_volume(mesh.nodes[k[0]], mesh.nodes[k[1]], mesh.nodes[k[2]], mesh.nodes[k[3]]);
}

// The smallest volume ratio (mesh/quality.hpp) of `tets`: a flip must not trade it away for
// the angle (a ring's long chord), as the smoothing's move must not (cut_smoothing.cpp).
double smallest_volume_ratio(const TetMesh& mesh, const std::vector<Tet>& tets) {
  double smallest = 1e300;
  for (const Tet& k : tets)
    smallest = std::min(smallest, volume_ratio(mesh.nodes[k[0]], mesh.nodes[k[1]], mesh.nodes[k[2]],
                                               mesh.nodes[k[3]]));
  return smallest;
}

// A replacement of the tets `cavity` by `tets` (positively oriented) over the same region.
struct Flip {
  bool face = false;  // a 2-3 flip (else an edge removal or an insertion)
  // A vertex insertion (vertex_insertion.hpp): `tets` use kInsertedNode for a new node at
  // `point`, inside the tet `host` at barycentric `weights`.
  bool insert = false;
  Vec3 point = Vec3::Zero();
  Tet host{};
  std::array<double, 4> weights{};
  std::vector<int> cavity;
  std::vector<Tet> tets;
  double size_class = 0;  // the smallest of the cavity's: the new tets'
  double before = 0;      // smallest dihedral angle of the cavity's tets
  double after = -1;      // of the new ones
};

// The cavity's smallest angle and size class; false if a tet of it is not cuttable.
bool describe_cavity(const TetMesh& mesh, const CutState& state, Flip& flip) {
  flip.before = 180;
  flip.size_class = 1e300;
  for (int t : flip.cavity) {
    if (!state.cuttable[static_cast<size_t>(t)]) return false;
    flip.before = std::min(flip.before, smallest_angle(mesh, mesh.tets[static_cast<size_t>(t)]));
    flip.size_class = std::min(flip.size_class, state.origin_volume[static_cast<size_t>(t)]);
  }
  return true;
}

// Every new tet positive and above the size guard, the same total volume (to round-off: the
// new tets then tile the cavity, their boundary being its boundary with its orientation).
bool tiles_cavity(const TetMesh& mesh, const Flip& flip, double min_volume) {
  double before = 0, after = 0;
  for (int t : flip.cavity) before += tet_volume(mesh, t);
  for (const Tet& k : flip.tets) {
    const double v = volume_of(mesh, k);
    if (!(v > min_volume)) return false;
    after += v;
  }
  return std::abs(after - before) <= 1e-12 * before;
}

// The 2-3 flip of face f of tet t: the tets (p, q, r, d) and (r, q, p, e) on either side of
// face pqr become (p, q, e, d), (q, r, e, d), (r, p, e, d) around edge de, which must cross pqr.
bool face_flip(const TetMesh& mesh, const CutState& state, int t, int f, double guard, Flip& flip) {
  if (mesh.is_cut_face(t, f)) return false;
  const auto [other, other_face] = neighbour_across(mesh, state, t, f);
  if (other < 0) return false;
  const Tet& k = mesh.tets[static_cast<size_t>(t)];
  const int d = k[static_cast<size_t>(f)],
            e = mesh.tets[static_cast<size_t>(other)][static_cast<size_t>(other_face)];
  int p = k[kTetFaces[f][0]], q = k[kTetFaces[f][1]], r = k[kTetFaces[f][2]];
  if (!(signed_volume(mesh.nodes[p], mesh.nodes[q], mesh.nodes[r], mesh.nodes[d]) > 0))
    std::swap(q, r);
  flip.cavity = {t, other};
  if (!describe_cavity(mesh, state, flip)) return false;
  flip.face = true;
  flip.tets = {Tet{p, q, e, d}, Tet{q, r, e, d}, Tet{r, p, e, d}};
  if (!tiles_cavity(mesh, flip, guard * flip.size_class)) return false;
  flip.after = 180;
  for (const Tet& n : flip.tets) flip.after = std::min(flip.after, smallest_angle(mesh, n));
  return true;
}

// Edge removal of (a, b): its ring p_0 .. p_m-1 (signed_volume(a, b, p_i, p_i+1) > 0) and the
// triangulation of the ring polygon whose tets (a, p_i, p_j, p_k), (b, p_k, p_j, p_i) (i < j < k)
// have the largest smallest angle, by dynamic programming over the polygon's sub-chains.
bool edge_removal(const TetMesh& mesh, const CutState& state, int a, int b, double guard,
                  Flip& flip) {
  const std::vector<int> ring_tets = tets_with_edge(state, a, b);
  const int m = static_cast<int>(ring_tets.size());
  if (m < 4 || m > kMaxRing) return false;
  // Each ring tet's two other corners; the faces through the edge must be on no cut.
  std::vector<std::array<int, 2>> pairs;
  for (int t : ring_tets) {
    const Tet& k = mesh.tets[static_cast<size_t>(t)];
    std::array<int, 2> other{};
    int n = 0;
    for (int i = 0; i < 4; ++i) {
      if (k[static_cast<size_t>(i)] == a || k[static_cast<size_t>(i)] == b) continue;
      other[static_cast<size_t>(n++)] = k[static_cast<size_t>(i)];
      if (mesh.is_cut_face(t, i)) return false;  // the face opposite this corner has the edge
    }
    pairs.push_back(other);
  }
  // Chain the pairs into one closed ring (an edge on the boundary leaves it open).
  std::vector<int> ring = {pairs[0][0], pairs[0][1]};
  std::vector<char> used(static_cast<size_t>(m), 0);
  used[0] = 1;
  for (int step = 1; step < m; ++step) {
    bool found = false;
    for (int i = 0; i < m && !found; ++i) {
      if (used[static_cast<size_t>(i)]) continue;
      for (int s = 0; s < 2; ++s)
        if (pairs[static_cast<size_t>(i)][static_cast<size_t>(s)] == ring.back()) {
          used[static_cast<size_t>(i)] = 1;
          if (step < m - 1)
            ring.push_back(pairs[static_cast<size_t>(i)][static_cast<size_t>(1 - s)]);
          else if (pairs[static_cast<size_t>(i)][static_cast<size_t>(1 - s)] != ring.front())
            return false;
          found = true;
          break;
        }
    }
    if (!found) return false;
  }
  if (static_cast<int>(ring.size()) != m) return false;
  const Vec3 &xa = mesh.nodes[static_cast<size_t>(a)], &xb = mesh.nodes[static_cast<size_t>(b)];
  if (!(signed_volume(xa, xb, mesh.nodes[static_cast<size_t>(ring[0])],
                      mesh.nodes[static_cast<size_t>(ring[1])]) > 0))
    std::reverse(ring.begin(), ring.end());
  flip.face = false;
  flip.cavity = ring_tets;
  if (!describe_cavity(mesh, state, flip)) return false;
  const double min_volume = guard * flip.size_class;
  // q[i][j][k]: the smallest angle of triangle (i, j, k)'s two tets, -1 if one is not positive.
  double q[kMaxRing][kMaxRing][kMaxRing];
  for (int i = 0; i < m; ++i)
    for (int j = i + 1; j < m; ++j)
      for (int k = j + 1; k < m; ++k) {
        const Tet ta{a, ring[static_cast<size_t>(i)], ring[static_cast<size_t>(j)],
                     ring[static_cast<size_t>(k)]};
        const Tet tb{b, ring[static_cast<size_t>(k)], ring[static_cast<size_t>(j)],
                     ring[static_cast<size_t>(i)]};
        q[i][j][k] = volume_of(mesh, ta) > min_volume && volume_of(mesh, tb) > min_volume
                         ? std::min(smallest_angle(mesh, ta), smallest_angle(mesh, tb))
                         : -1;
      }
  // best[i][j]: the best smallest angle over triangulations of the chain i..j (j - i >= 2),
  // apex[i][j] the k that achieves it.
  double best[kMaxRing][kMaxRing];
  int apex[kMaxRing][kMaxRing];
  for (int span = 2; span < m; ++span)
    for (int i = 0; i + span < m; ++i) {
      const int j = i + span;
      best[i][j] = -1;
      apex[i][j] = -1;
      for (int k = i + 1; k < j; ++k) {
        double v = q[i][k][j];
        if (k - i >= 2) v = std::min(v, best[i][k]);
        if (j - k >= 2) v = std::min(v, best[k][j]);
        if (v > best[i][j]) best[i][j] = v, apex[i][j] = k;
      }
    }
  if (!(best[0][m - 1] > 0)) return false;
  flip.tets.clear();
  std::vector<std::array<int, 2>> chains = {{0, m - 1}};
  while (!chains.empty()) {
    const auto [i, j] = chains.back();
    chains.pop_back();
    const int k = apex[i][j];
    flip.tets.push_back(Tet{a, ring[static_cast<size_t>(i)], ring[static_cast<size_t>(k)],
                            ring[static_cast<size_t>(j)]});
    flip.tets.push_back(Tet{b, ring[static_cast<size_t>(j)], ring[static_cast<size_t>(k)],
                            ring[static_cast<size_t>(i)]});
    if (k - i >= 2) chains.push_back({i, k});
    if (j - k >= 2) chains.push_back({k, j});
  }
  if (!tiles_cavity(mesh, flip, min_volume)) return false;
  flip.after = best[0][m - 1];
  return true;
}

Flip as_flip(const VertexInsertion& insertion) {
  Flip flip;
  flip.insert = true;
  flip.cavity = insertion.cavity;
  flip.tets = insertion.tets;
  flip.size_class = insertion.size_class;
  flip.before = insertion.before;
  flip.after = insertion.after;
  flip.point = insertion.point;
  flip.host = insertion.host;
  flip.weights = insertion.weights;
  return flip;
}

// The last stroke's triangles (CutState::last_sweep, margins included). The same path cut once
// more (a repeated `~cut`, which must then find nothing left to cut:
// `RepeatedCutSaysItIsAlreadyCut` cut in 5 passes in a row with unrestricted flips) splits an edge
// that crosses them and marks a closed face on them whose two tets' opposite corners come to lie on
// either side. So no flip replaces a tet with a closed face lying on the triangles (holds: its
// corners within the snap distance, 0.1 of its longest edge, of a plane, over the triangle or a
// quarter of it beyond, where the borders are split): where the cut surface is made of faces, a new
// edge that crossed it would cross such a face inside the cavity. (Also refusing new edges that
// come within the snap distance of a plane cost half the flips' gain, 939 -> 1,087 tets under 5 deg
// over `QualityAfter100Cuts`' 12 runs, and the repeated cut settles without it.)
class SweptSurface {
 public:
  explicit SweptSurface(const std::vector<std::array<Vec3, 3>>& triangles) {
    for (const auto& t : triangles) {
      const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
      const double diameter =
          std::max({(t[1] - t[0]).norm(), (t[2] - t[1]).norm(), (t[0] - t[2]).norm()});
      if (!(n.norm() > 1e-12 * diameter * diameter)) continue;  // a plunge sweeps nothing
      const Vec3 pad = Vec3::Constant(kOverSlack * diameter);
      triangles_.push_back({t, n.normalized(), n.norm(), t[0].cwiseMin(t[1]).cwiseMin(t[2]) - pad,
                            t[0].cwiseMax(t[1]).cwiseMax(t[2]) + pad});
    }
  }

  // Do all of a face's corners lie within `near` of one triangle's plane, over it?
  bool holds(const Vec3& a, const Vec3& b, const Vec3& c, double near) const {
    for (const Triangle& t : triangles_) {
      bool all = true;
      for (const Vec3* x : {&a, &b, &c}) {
        if ((x->array() < t.lo.array() - near).any() || (x->array() > t.hi.array() + near).any() ||
            std::abs(t.normal.dot(*x - t.corner[0])) > near || !over(t, *x, kOverSlack)) {
          all = false;
          break;
        }
      }
      if (all) return true;
    }
    return false;
  }

 private:
  // Barycentric slack of "over a triangle": the cut's borders are split a quarter of an element
  // beyond the sweep (cut_sweep.cpp), so its neighbourhood counts too.
  static constexpr double kOverSlack = 0.25;
  struct Triangle {
    std::array<Vec3, 3> corner;
    Vec3 normal;
    double double_area;
    Vec3 lo, hi;
  };
  std::vector<Triangle> triangles_;

  static bool over(const Triangle& t, const Vec3& x, double slack) {
    const double u = t.normal.dot((t.corner[1] - x).cross(t.corner[2] - x)) / t.double_area;
    const double v = t.normal.dot((t.corner[2] - x).cross(t.corner[0] - x)) / t.double_area;
    return u >= -slack && v >= -slack && 1 - u - v >= -slack;
  }
};

// Replaces the cavity's tets: its indices first (ascending), then appended ones; the cut marks
// of its boundary faces go to the new tets that have those faces (the faces inside were on no
// cut). Returns the new tets' indices.
std::vector<int> apply(TetMesh& mesh, CutState& state, Flip flip, CutResult& result) {
  if (flip.insert) {  // the new node first, its displacement interpolated in `host` (eq. (21a))
    NewNode node;
    node.index = mesh.num_nodes();
    node.kind = NewNode::Kind::kInTet;
    node.corners = flip.host;
    node.weights = flip.weights;
    mesh.nodes.push_back(flip.point);
    state.locked.push_back(0);
    state.node_tets.emplace_back();
    result.new_nodes.push_back(node);
    ++result.nodes_inserted;
    for (Tet& k : flip.tets)
      for (int& v : k)
        if (v == kInsertedNode) v = node.index;
  }
  std::set<FaceKey> marked;
  for (int t : flip.cavity) {
    const Tet& k = mesh.tets[static_cast<size_t>(t)];
    for (int f = 0; f < 4; ++f)
      if (mesh.is_cut_face(t, f)) {
        marked.insert(face_key(k, f));
      }
    for (int v : k) {
      auto& star = state.node_tets[static_cast<size_t>(v)];
      star.erase(std::find(star.begin(), star.end(), t));
    }
  }
  std::vector<int> indices = flip.cavity;
  std::sort(indices.begin(), indices.end());
  for (size_t n = 0; n < flip.tets.size(); ++n) {
    int t = 0;
    if (n < indices.size()) {
      t = indices[n];
      mesh.tets[static_cast<size_t>(t)] = flip.tets[n];
    } else {
      t = mesh.num_tets();
      indices.push_back(t);
      mesh.tets.push_back(flip.tets[n]);
      mesh.cut_faces.push_back(0);
      state.cuttable.push_back(1);
      state.origin_volume.push_back(flip.size_class);
    }
    std::uint8_t bits = 0;
    const Tet& k = flip.tets[n];
    for (int f = 0; f < 4; ++f) {
      if (marked.count(face_key(k, f))) bits |= static_cast<std::uint8_t>(1u << f);
    }
    mesh.cut_faces[static_cast<size_t>(t)] = bits;
    for (int i = 0; i < 4; ++i)  // a new edge may be longer than any before (the bound holds)
      for (int j = i + 1; j < 4; ++j)
        state.longest_edge_bound = std::max(
            state.longest_edge_bound, (mesh.nodes[static_cast<size_t>(k[static_cast<size_t>(i)])] -
                                       mesh.nodes[static_cast<size_t>(k[static_cast<size_t>(j)])])
                                          .norm());
    state.origin_volume[static_cast<size_t>(t)] = flip.size_class;
    for (int v : k) state.node_tets[static_cast<size_t>(v)].push_back(t);
    state.grid.insert(mesh, t);  // a kept index's new box may lie in other cells
  }
  return indices;
}

// The best flip that removes tet t (through its faces or around its edges), if any gains.
bool best_flip(const TetMesh& mesh, const CutState& state, int t, const CutOptions& options,
               const SweptSurface& swept, Flip& best) {
  const double guard = 2 * options.min_volume_fraction, snap = options.snap_tolerance;
  bool found = false;
  const auto disturbs_last_stroke = [&](const Flip& candidate) {
    // A closed face of the cavity on the stroke's surface (SweptSurface): one between two of
    // its tets too, which a new edge would cross.
    for (int c : candidate.cavity)
      for (int f = 0; f < 4; ++f) {
        if (mesh.is_cut_face(c, f)) continue;
        const Tet& k = mesh.tets[static_cast<size_t>(c)];
        const Vec3 &a = mesh.nodes[static_cast<size_t>(k[kTetFaces[f][0]])],
                   &b = mesh.nodes[static_cast<size_t>(k[kTetFaces[f][1]])],
                   &d = mesh.nodes[static_cast<size_t>(k[kTetFaces[f][2]])];
        const double longest = std::max({(a - b).norm(), (b - d).norm(), (d - a).norm()});
        if (swept.holds(a, b, d, snap * longest)) return true;
      }
    return false;
  };
  const auto ratio_kept = [&](const Flip& candidate) {
    if (candidate.insert) return true;  // vertex_insertion kept it (its tets name no node yet)
    std::vector<Tet> old;
    for (int c : candidate.cavity) old.push_back(mesh.tets[static_cast<size_t>(c)]);
    return smallest_volume_ratio(mesh, candidate.tets) >= smallest_volume_ratio(mesh, old);
  };
  const auto consider = [&](Flip& candidate) {
    if (candidate.after > candidate.before + kFlipGainDeg && ratio_kept(candidate) &&
        (!found || candidate.after > best.after) && !disturbs_last_stroke(candidate)) {
      best = candidate;
      found = true;
    }
  };
  Flip candidate;
  for (int f = 0; f < 4; ++f)
    if (face_flip(mesh, state, t, f, guard, candidate)) consider(candidate);
  const Tet& k = mesh.tets[static_cast<size_t>(t)];
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
      if (edge_removal(mesh, state, k[static_cast<size_t>(i)], k[static_cast<size_t>(j)], guard,
                       candidate))
        consider(candidate);
  // No flip brings the tet to the threshold: a node inside a cavity around it may.
  if (options.insert_nodes && (!found || best.after < options.smooth_below_deg))
    for (const std::vector<int>& cavity : insertion_cavities(mesh, state, t)) {
      VertexInsertion insertion;
      if (!vertex_insertion(mesh, state, cavity, guard, insertion)) continue;
      candidate = as_flip(insertion);
      consider(candidate);
    }
  return found;
}

}  // namespace

int apply_insertion(TetMesh& mesh, CutState& state, const VertexInsertion& insertion,
                    CutResult& result, bool shape) {
  const int node = mesh.num_nodes();
  const std::vector<int> changed = apply(mesh, state, as_flip(insertion), result);
  if (!shape) --result.nodes_inserted;
  result.changed_tets.insert(result.changed_tets.end(), changed.begin(), changed.end());
  return node;
}

void apply_star(TetMesh& mesh, CutState& state, const VertexInsertion& star, CutResult& result) {
  Flip flip = as_flip(star);
  flip.insert = false;  // its tets hold the apex, a node of the mesh
  const std::vector<int> changed = apply(mesh, state, flip, result);
  result.changed_tets.insert(result.changed_tets.end(), changed.begin(), changed.end());
}

FlipCounts flip_thin_tets(TetMesh& mesh, CutState& state, const CutOptions& options,
                          const std::vector<int>& tets, CutResult& result) {
  FlipCounts flips;
  if (!(options.smooth_below_deg > 0)) return flips;
  const SweptSurface swept(state.last_sweep);
  std::vector<int> queue = tets;
  // Two rounds: the second over the tets the first made (a flip's new tets may flip again).
  for (int round = 0; round < 2 && !queue.empty(); ++round) {
    std::sort(queue.begin(), queue.end());
    queue.erase(std::unique(queue.begin(), queue.end()), queue.end());
    std::vector<int> made;
    for (int t : queue) {
      if (t >= mesh.num_tets() ||
          smallest_angle(mesh, mesh.tets[static_cast<size_t>(t)]) >= options.smooth_below_deg)
        continue;
      Flip flip;
      if (!best_flip(mesh, state, t, options, swept, flip)) continue;
      const std::vector<int> changed = apply(mesh, state, flip, result);
      result.changed_tets.insert(result.changed_tets.end(), changed.begin(), changed.end());
      made.insert(made.end(), changed.begin(), changed.end());
      ++(flip.insert ? flips.insertions : flip.face ? flips.faces : flips.edges);
    }
    queue = std::move(made);
  }
  return flips;
}

}  // namespace stc
