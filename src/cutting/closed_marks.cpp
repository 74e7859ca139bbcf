#include "cutting/closed_marks.hpp"

#include "cutting/edge_bisection.hpp"
#include "cutting/separation.hpp"
#include "cutting/triangle_cut.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace stc {
namespace {

// The shape guard on these splits (as CutOptions::split_min_dihedral_deg, at least this): they
// are made for the opening, not to follow the blade, so they may be refused where the cut's own
// may not. Measured (stop 45) over 100 random strokes on the sagging TetGen liver, seeds
// 20261123 and 1-4: tets under 5 deg 612 without the opening, 796 with it under the scene's
// 1 deg, 691 with 5 deg, 665 with 10 deg; the 40 strokes of the fidelity matrix' summed excess
// over the Hausdorff tolerance 6.29, 5.16, 5.38, 5.75.
constexpr double kOpeningGuardDeg = 5.0;
// Where along an edge an opening split is tried, in order.
constexpr double kOpeningSplits[] = {0.5, 0.4, 0.6, 0.3, 0.7, 0.2, 0.8};

// Bisects edge (a, b) at its midpoint if it still exists and every tet on it is cuttable and
// passes the guards (kOpeningGuardDeg); returns the new node or -1.
int split_midpoint(TetMesh& mesh, CutState& state, int a, int b, const CutOptions& options,
                   CutResult& result) {
  if (state.locked[static_cast<size_t>(a)] && state.locked[static_cast<size_t>(b)]) return -1;
  const std::vector<int> ring = tets_with_edge(state, a, b);
  if (ring.empty()) return -1;
  CutOptions guarded = options;
  guarded.split_min_dihedral_deg = std::max(options.split_min_dihedral_deg, kOpeningGuardDeg);
  for (int t : ring)
    if (!state.cuttable[static_cast<size_t>(t)]) return -1;
  // The midpoint, else the nearest place to it along the edge the guards allow (the node's fan
  // is the marks' two parts wherever it lies on the edge).
  for (double at : kOpeningSplits) {
    if (!options.opening_split_shift && at != 0.5) break;
    if (std::any_of(ring.begin(), ring.end(),
                    [&](int t) { return split_too_thin(mesh, state, t, a, b, at, guarded); }))
      continue;
    const size_t before = result.changed_tets.size();
    const int m = bisect_edge(mesh, state, a, b, at, result.changed_tets);
    result.tets_split += static_cast<int>(result.changed_tets.size() - before) / 2;
    set_on_stroke(state, m);
    set_opened_at_end(state, m);
    result.new_nodes.push_back(NewNode::on_edge(m, a, b, at));
    return m;
  }
  return -1;
}

// One round: round 0 splits an edge that another mark shares, round 1 (what round 0's marks
// still hold shut) an edge that an opened wall shares.
int open_round(TetMesh& mesh, CutState& state, const std::vector<int>& tets,
               const CutOptions& options, CutResult& result, int round, int first_new) {
  // The marked faces around the stroke, closed ones apart, and how many marks use each edge.
  std::set<FaceKey> closed, marked, opened;
  std::map<FaceKey, double> size_class;  // the origin volume of a tet on the face
  for (int t : tets) {
    if (t < 0 || t >= mesh.num_tets() || !state.cuttable[static_cast<size_t>(t)]) continue;
    for (int f = 0; f < 4; ++f) {
      if (!mesh.is_cut_face(t, f)) continue;
      const FaceKey key = face_key(mesh.tets[static_cast<size_t>(t)], f);
      marked.insert(key);
      (neighbour_across(mesh, state, t, f).first >= 0 ? closed : opened).insert(key);
      size_class[key] = state.origin_volume[static_cast<size_t>(t)];
    }
  }
  if (closed.empty()) return 0;
  std::map<std::pair<int, int>, int> uses;
  for (const FaceKey& k : round == 0 ? marked : opened)
    for (int e = 0; e < 3; ++e)
      ++uses[{std::min(k[e], k[(e + 1) % 3]), std::max(k[e], k[(e + 1) % 3])}];
  const size_t nodes_before = result.new_nodes.size();
  std::vector<int> added;
  const StrokeSurface surface(state.blade_sweep);
  for (const FaceKey& k : closed) {
    // Only a face along the stroke's surface (its corners within kOnCutSlack of its longest
    // edge - or of the edge of the input tet it was split from, CutOptions::
    // open_marks_at_input_scale - no skin slack): a mark left closed may reach farther, and
    // opened it would be a wall off the blade's path.
    double face_longest = 0;
    for (int e = 0; e < 3; ++e)
      face_longest = std::max(face_longest, (mesh.nodes[k[e]] - mesh.nodes[k[(e + 1) % 3]]).norm());
    bool along = true;
    for (int v : k)  // made at an earlier stroke's end (this one's second round may use its own)
      along = along && !(v < first_new && was_opened_at_end(state, v));
    // The input tet's edge: a regular tet's of its volume (the size class).
    const double original_edge = std::cbrt(6 * std::sqrt(2.0) * size_class[k]);
    const double scale =
        options.open_marks_at_input_scale ? std::max(face_longest, original_edge) : face_longest;
    for (int e = 0; e < 3 && along; ++e)
      along = surface.near(mesh.nodes[k[e]], kOnCutSlack * scale);
    if (!along) continue;
    // The face's longest edge another mark shares.
    int best = -1;
    double longest = 0;
    for (int e = 0; e < 3; ++e) {
      const int a = k[e], b = k[(e + 1) % 3];
      if (uses[{std::min(a, b), std::max(a, b)}] < (round == 0 ? 2 : 1)) continue;
      const double length = (mesh.nodes[a] - mesh.nodes[b]).norm();
      if (length > longest) longest = length, best = e;
    }
    if (best >= 0) {
      const int m = split_midpoint(mesh, state, k[best], k[(best + 1) % 3], options, result);
      if (m >= 0) {
        added.push_back(m);
        continue;
      }
      if (!options.open_marks_at_centre) continue;
    }
    if (round > 0) continue;
    // A face alone, or one whose shared edge the guards keep whole (a corner's face at the
    // blade's tip, tip_corner.hpp): its centre, as the midpoint of (the longest edge's
    // midpoint, the far corner).
    longest = 0;
    for (int e = 0; e < 3; ++e) {
      const double length = (mesh.nodes[k[e]] - mesh.nodes[k[(e + 1) % 3]]).norm();
      if (length > longest) longest = length, best = e;
    }
    const int m = split_midpoint(mesh, state, k[best], k[(best + 1) % 3], options, result);
    if (m < 0) continue;
    added.push_back(m);
    const int c = k[(best + 2) % 3];
    const int n = split_midpoint(mesh, state, m, c, options, result);
    if (n >= 0) added.push_back(n);
  }
  if (added.empty()) return 0;
  std::vector<int> region;
  for (int v : added)
    for (int t : state.node_tets[static_cast<size_t>(v)])
      for (int w : mesh.tets[static_cast<size_t>(t)])
        region.insert(region.end(), state.node_tets[static_cast<size_t>(w)].begin(),
                      state.node_tets[static_cast<size_t>(w)].end());
  std::sort(region.begin(), region.end());
  region.erase(std::unique(region.begin(), region.end()), region.end());
  std::set<FaceKey> new_faces;
  separate_along_cuts(mesh, state, region, result, new_faces);
  return static_cast<int>(result.new_nodes.size() - nodes_before);
}

}  // namespace

int open_closed_marks(TetMesh& mesh, CutState& state, const std::vector<int>& tets,
                      const CutOptions& options, CutResult& result) {
  const int first_new = mesh.num_nodes();
  // The stroke's tets repeat (CutState::stroke_tets): each once, and for the second round with
  // those the first one changed.
  const auto unique = [](std::vector<int> v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    return v;
  };
  std::vector<int> now = unique(tets);
  int added = open_round(mesh, state, now, options, result, 0, first_new);
  // Then what the opened walls still hold shut, again while that opens more (a face split
  // at its centre leaves a third of it on the border: the tip's corner, tip_corner.hpp).
  for (int round = 1, last = added; round <= options.opening_rounds && (round == 1 || last > 0);
       ++round) {
    now.insert(now.end(), result.changed_tets.begin(), result.changed_tets.end());
    now = unique(std::move(now));
    last = open_round(mesh, state, now, options, result, 1, first_new);
    added += last;
  }
  return added;
}

}  // namespace stc
