// Inserting planar cut triangles into the tet mesh (steps a-c of the cut), in two phases:
//   1. split_along_triangle: classify nodes against the triangle's plane (snapping the near
//      ones to "on"), bisect the edges that cross the triangle;
//   2. mark_faces_on_triangle: mark the faces that now lie on it.
// All triangles of a cut are split before any is marked, because splits for one triangle
// create faces on a neighbouring one (near their shared edge) that its own split phase never
// saw. Separation (separation.hpp) comes after.
#pragma once

#include "cutting/cut_state.hpp"
#include "soft_tissue_cutting/cutting/cut_result.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <set>
#include <unordered_map>
#include <vector>

namespace stc {

using FaceKey = std::array<int, 3>;  // sorted node triple

// Local face f of `tet` as a FaceKey.
inline FaceKey face_key(const Tet& tet, int f) {
  FaceKey key = {tet[kTetFaces[f][0]], tet[kTetFaces[f][1]], tet[kTetFaces[f][2]]};
  std::sort(key.begin(), key.end());
  return key;
}

// Each node's longest edge (the scale its "on the cut" test is relative to), computed on
// demand and kept while the mesh does not change: the mark phase classifies the same nodes
// against every earlier triangle of a stroke (hundreds for a slow blade), and recomputing the
// star's edges for each was most of a follow-mode cut step.
class NodeScales {
 public:
  double longest_edge(const TetMesh& mesh, const CutState& state, int v);

 private:
  std::vector<double> longest_;  // < 0: not computed yet
};

// A cut triangle and the sides its split phase gave the nodes (-1, +1, or 0 = on the cut).
// Nodes not yet classified are classified on demand with the same snap rule.
class TriangleClassification {
 public:
  TriangleClassification(const Vec3& a, const Vec3& b, const Vec3& c, double snap_tolerance);
  // From now on the nodes' scales come from (and go to) `scales`: only once the mesh stops
  // changing (the mark phase; splits change the stars).
  void share_scales(NodeScales* scales) { scales_ = scales; }
  bool degenerate() const { return degenerate_; }
  // Is the projection of p onto the plane inside the triangle, with barycentric slack tol?
  bool contains(const Vec3& p, double tol) const;
  double distance(const TetMesh& mesh, int v) const { return normal_.dot(mesh.nodes[v] - a_); }
  int side(const TetMesh& mesh, const CutState& state, int v);
  void set_on(int v) { side_[v] = 0; }
  const Vec3& normal() const { return normal_; }
  Vec3 centroid() const { return (a_ + b_ + c_) / 3.0; }
  void bounds(Vec3& lo, Vec3& hi) const;

 private:
  Vec3 a_, b_, c_, normal_;
  double double_area_ = 0, snap_tolerance_ = 0;
  bool degenerate_ = false;
  std::unordered_map<int, int> side_;
  NodeScales* scales_ = nullptr;
};

// The stroke's surface as the mark phase tests a face's corners against it: its triangles
// with their boxes, and what is known of each node's distance to them (the mark phase asks
// about the same corners for every earlier triangle of a slow stroke; the mesh no longer
// changes while it runs).
class StrokeSurface {
 public:
  explicit StrokeSurface(const std::vector<std::array<Vec3, 3>>& triangles);
  const std::vector<std::array<Vec3, 3>>& triangles() const { return triangles_; }
  // Is x within `slack` of one of the triangles?
  bool near(const Vec3& x, double slack) const { return first_within(x, slack) >= 0; }
  // The same for node v, from what is known of it where that answers (mark phase only).
  bool near_node(const TetMesh& mesh, int v, double slack);
  // May node v be a corner of a face on the stroke's surface: within `slack` of it, or on the
  // tissue's boundary and within skin_slack x slack (mark_face_on_triangle)? Mark phase only:
  // the tets do not change while it runs, so whether v is on the boundary (a walk of its
  // star) is found once, and only for nodes near enough for it to matter - it had been asked
  // for every corner of every candidate face, 16 % of an organ cutting step (callgrind).
  // with_limits false: the triangles' distance alone (add_limit's limits not asked).
  bool corner_near(const TetMesh& mesh, const CutState& state, int v, double slack,
                   double skin_slack, bool with_limits = true);
  bool limited() const { return !limits_.empty(); }
  // The faces refused only by a limit (they lie past where the blade is now): the stroke
  // tests them again as the blade moves on (mark_deferred_faces).
  void defer(const FaceKey& face) { deferred_.push_back(face); }
  const std::vector<FaceKey>& deferred() const { return deferred_; }
  // Where the blade stands as a polyline (its edge, tip first; or the path its tip or heel
  // took) and which way "past it" is at each of its points (unit: the edge's motion, or down
  // the blade past the tip, up past the heel; 0 where none): a corner may lie at most `reach` +
  // `slack_fraction` x its slack past it (corner_near), whatever its distance to the
  // triangles. Without a limit a corner is limited only by that distance, which reaches past
  // the blade by the triangles' margin plus the slack. Several limits all hold.
  void add_limit(std::vector<Vec3> line, std::vector<Vec3> past, double reach,
                 double slack_fraction);

 private:
  // The distance to the first triangle (in order: nearest first) within slack, or -1.
  double first_within(const Vec3& x, double slack) const;

  struct Limit {
    std::vector<Vec3> line, past;
    double reach = 0, slack_fraction = 0;
    // How far x lies past the line (along its nearest point's direction; < 0 short of it).
    double past_of(const Vec3& x) const;
  };
  // The edge's front, the tip's and heel's paths, the stroke's start.
  static constexpr size_t kMaxLimits = 4;

  std::vector<std::array<Vec3, 3>> triangles_;
  std::vector<Vec3> lo_, hi_;
  std::vector<Limit> limits_;
  std::vector<FaceKey> deferred_;
  // A triangle within near_at (near for every slack >= it); none within far_below.
  struct Known {
    double near_at = std::numeric_limits<double>::infinity(), far_below = -1;
    // How far past each limit's line (NaN: not asked yet).
    std::array<double, kMaxLimits> past = {
        std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
        std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
    std::int8_t on_boundary = -1;  // -1: not asked yet
  };
  std::unordered_map<int, Known> known_;
};

// How far (in units of its longest edge) a face marked on the cut may lie off the stroke's
// surface: its centroid off the triangle's plane, its corners off every triangle of the stroke.
constexpr double kOnCutSlack = 0.25;

// How much farther from the stroke's surface a face's corner on the tissue's boundary may lie
// than an interior one while the blade sweeps (mark_faces_on_triangle). Without it a shallow
// stroke along a sagging liver's top (every cut face has a skin corner) opened 71 % of its
// swept area instead of 146 %.
constexpr double kSkinCornerSlack = 4.0;

// Phase 1. Splits only edges that are not interface edges (both ends locked) and whose
// crossing point is inside the triangle, or that belong to a tet of `whole` (sorted: tets cut
// by the whole plane); new nodes, split counts and changed tets go to `result`.
void split_along_triangle(TetMesh& mesh, CutState& state, TriangleClassification& triangle,
                          const CutOptions& options, CutResult& result,
                          const std::vector<int>& whole = {});

// Phase 1b. The border of the cut surface, conformed. Without it a tet that segment p0-p1 of
// the triangle's border runs through is cut only part way, no face of it lies wholly on the
// cut, and the opening ends up to an element short of where the blade went. So the tets the
// segment crosses are cut by the triangle's whole plane (phase 1 with `whole`), and then the
// edges that lie on the cut (both ends "on") and cross the segment are split where they do
// (t in [snap, 1 - snap], the volume guard as in phase 1): every face on the cut then lies on
// one side of the border (docs/DESIGN.md section 8, eq. (19a)).
// surface: the stroke's triangles (as mark_faces_on_triangle); a tet is cut by the whole plane
// only where its crossings on the sweep's side of the border lie on that surface, or the
// surface is flat across the tet (a curved or tilted stroke's surface turns away from one
// triangle's plane across a large tet; a straight one's may just end inside it).
// tip_path: the segment is a piece of the path the tip took; an edge end within
// CutOptions::path_border_snap of the snap distance from the plane then counts as on the cut.
void split_along_border(TetMesh& mesh, CutState& state, TriangleClassification& triangle,
                        const Vec3& p0, const Vec3& p1, const CutOptions& options,
                        const StrokeSurface& surface, CutResult& result, bool tip_path = false);

// Phase 2. Marks interior faces between two cuttable tets with three "on" nodes, the tets'
// fourth nodes on opposite sides and the centroid inside the triangle, among the tets that
// overlap [lo, hi]. Newly marked faces are added to `new_faces`.
// surface: every triangle of the stroke so far (this cut's and the earlier ones); a face is
// marked only if its corners lie on it up to the snap distance, so no face reaching past the
// blade's path opens (the centroid rule alone would open a face straddling a border).
// skin_slack: a corner on the tissue's boundary may lie that many times farther from the
// surface (kSkinCornerSlack while the blade sweeps; 1 at a stroke's end, finish_stroke).
void mark_faces_on_triangle(TetMesh& mesh, const CutState& state, TriangleClassification& triangle,
                            const Vec3& lo, const Vec3& hi, const CutOptions& options,
                            StrokeSurface& surface, double skin_slack, CutResult& result,
                            std::set<FaceKey>& new_faces);

// Phase 2 for one face: local face f of tet t, by the tests above (whatever the tet's other
// faces).
void mark_face_on_triangle(TetMesh& mesh, const CutState& state, TriangleClassification& triangle,
                           int t, int f, const CutOptions& options, StrokeSurface& surface,
                           double skin_slack, CutResult& result, std::set<FaceKey>& new_faces);

// Phase 2 for faces an earlier cut of the stroke refused only because a corner lay past the
// blade (StrokeSurface::defer): each that is still a face between two cuttable tets, and whose
// corners now pass `surface`'s tests (the blade has moved on), is marked. A corner of such a face
// may be "on" only for the triangle that refused it - one snapped onto its plane past the
// stroke's start - so no later triangle's mark phase would find it again (the thigh's tilted
// strokes and the 50k liver's: a 3.7 mm hole at the start). The others (still refused) are
// returned; faces that no longer exist are dropped.
std::vector<FaceKey> mark_deferred_faces(TetMesh& mesh, const CutState& state,
                                         const std::vector<FaceKey>& faces, StrokeSurface& surface,
                                         double skin_slack, std::set<FaceKey>& new_faces,
                                         double wedge_min_deg = CutOptions{}.wedge_min_deg);

// Would bisecting edge (a, b) of tet t at x_a + s (x_b - x_a) leave a piece under the volume
// guard or the shape guard (CutOptions::min_volume_fraction, split_min_dihedral_deg), as the
// splits above are checked?
bool split_too_thin(const TetMesh& mesh, const CutState& state, int t, int a, int b, double s,
                    const CutOptions& options);

// The cuttable tets whose boxes overlap [lo, hi].
std::vector<int> cuttable_tets_in(const TetMesh& mesh, const CutState& state, const Vec3& lo,
                                  const Vec3& hi);

// The tet across local face `face` of `tet` and that tet's local index of the face, or
// {-1, -1} on the boundary.
std::pair<int, int> neighbour_across(const TetMesh& mesh, const CutState& state, int tet, int face);

}  // namespace stc
