// docs/DESIGN.md section 8, "Smooth" (eq. (20b)): after a stroke, nodes of thin tets move inside
// their stars (interior nodes) or within a flat fan of boundary faces, raising the smallest
// dihedral angle of their star, without moving any surface or changing the volume.
#include "common/cut_measures.hpp"
#include "cutting/cut_smoothing.hpp"
#include "cutting/cut_state.hpp"
#include "cutting/cut_sweep.hpp"
#include "cutting/node_moves.hpp"
#include "soft_tissue_cutting/collision/blade.hpp"
#include "soft_tissue_cutting/cutting/invariants.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/mesh/boundary_surface.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

namespace stc {
namespace {

// A 6 x 6 x 6-cell box, 1 cm cells (Kuhn split: 18-45 deg dihedral angles uncut).
TetMesh box() {
  GeneratorParams g;
  g.size = Vec3(0.06, 0.06, 0.06);
  g.cells = {6, 6, 6};
  return make_box_mesh(g);
}

int node_at(const TetMesh& mesh, const Vec3& x) {
  int best = 0;
  for (int v = 1; v < mesh.num_nodes(); ++v)
    if ((mesh.nodes[v] - x).norm() < (mesh.nodes[best] - x).norm()) best = v;
  return best;
}

double surface_area(const TetMesh& mesh) {
  double area = 0;
  for (const BoundaryTriangle& t : extract_boundary_surface(mesh).triangles)
    area += 0.5 * (mesh.nodes[t.nodes[1]] - mesh.nodes[t.nodes[0]])
                      .cross(mesh.nodes[t.nodes[2]] - mesh.nodes[t.nodes[0]])
                      .norm();
  return area;
}

double star_min_dihedral(const TetMesh& mesh, const CutState& state, int v) {
  return star_smallest_dihedral(mesh, state, v, mesh.nodes[v], -1e300);
}

// Smooths v's star as if a stroke had just changed it.
CutResult smooth_star(TetMesh& mesh, CutState& state, int v) {
  state.stroke_tets = state.node_tets[v];
  CutResult result;
  smooth_last_stroke(mesh, state, CutOptions{}, result);
  return result;
}

TEST(CutSmoothing, AnInteriorNodeMovesOutOfTheSliversAroundIt) {
  TetMesh mesh = box();
  CutState state = make_cut_state(mesh, {}, {});
  const double volume = total_volume(mesh);
  const int v = node_at(mesh, Vec3(0.03, 0.03, 0.03));
  // Pushed 90 % of the way towards its neighbour along x: its star is thin.
  const Vec3 home = mesh.nodes[v];
  mesh.nodes[v] = home + Vec3(0.009, 0, 0);
  const double before = star_min_dihedral(mesh, state, v);
  ASSERT_LT(before, 5.0);
  const TetMesh unsmoothed = mesh;
  std::vector<char> on_boundary(mesh.nodes.size(), 0);
  for (const BoundaryTriangle& t : extract_boundary_surface(mesh).triangles)
    for (int w : t.nodes) on_boundary[w] = 1;
  const CutResult r = smooth_star(mesh, state, v);
  const double after = star_min_dihedral(mesh, state, v);
  std::printf("interior node: star's smallest dihedral %.2f -> %.2f deg, moved %.2f mm back\n",
              before, after, 1e3 * (mesh.nodes[v] - home).norm());
  EXPECT_GT(after, 15.0);
  // v and the other corners of its thin tets moved (interior nodes all), nothing else.
  EXPECT_NE(std::find(r.moved_nodes.begin(), r.moved_nodes.end(), v), r.moved_nodes.end());
  for (int w = 0; w < mesh.num_nodes(); ++w) {
    const bool moved =
        std::find(r.moved_nodes.begin(), r.moved_nodes.end(), w) != r.moved_nodes.end();
    EXPECT_EQ(mesh.nodes[w] != unsmoothed.nodes[w], moved) << "node " << w;
    if (!moved) continue;
    EXPECT_FALSE(on_boundary[w]) << "node " << w;
    if (w == v) continue;
    EXPECT_FALSE(tets_with_edge(state, v, w).empty()) << "node " << w;
  }
  EXPECT_NEAR(total_volume(mesh), volume, 1e-12 * volume);
  EXPECT_TRUE(state.stroke_tets.empty());  // the stroke's tets are forgotten
}

// v, pushed off where its star is best, may slide (how_node_may_move says `kind`, its axis along
// coordinate `axis_dim`): the smoothing raises its star's smallest angle by more than 5 deg and
// keeps the volume and the boundary's area exact.
void expect_slides(TetMesh& mesh, CutState& state, int v, NodeMove kind, int axis_dim,
                   const char* label) {
  const double volume = total_volume(mesh);
  const double area = surface_area(mesh);
  Vec3 axis;
  ASSERT_EQ(how_node_may_move(mesh, state, v, axis), kind) << label;
  EXPECT_FALSE(may_move_inside_star(mesh, state, v)) << label;
  EXPECT_NEAR(std::abs(axis[axis_dim]), 1.0, 1e-12) << label;
  const double before = star_min_dihedral(mesh, state, v);
  smooth_star(mesh, state, v);
  const double after = star_min_dihedral(mesh, state, v);
  std::printf("%s: star's smallest dihedral %.2f -> %.2f deg\n", label, before, after);
  EXPECT_GT(after, before + 5.0) << label;
  EXPECT_NEAR(total_volume(mesh), volume, 1e-12 * volume) << label;
  EXPECT_NEAR(surface_area(mesh), area, 1e-12 * area) << label;
}

TEST(CutSmoothing, ANodeOnAFlatFaceSlidesWithinIt) {
  TetMesh mesh = box();
  CutState state = make_cut_state(mesh, {}, {});
  // A node of the z = 0 face, pushed within the face towards a neighbour.
  const int v = node_at(mesh, Vec3(0.03, 0.03, 0.0));
  mesh.nodes[v] += Vec3(0.009, 0, 0);
  ASSERT_EQ(mesh.nodes[v].z(), 0.0);
  expect_slides(mesh, state, v, NodeMove::kInPlane, 2, "face node");
  EXPECT_EQ(mesh.nodes[v].z(), 0.0);  // still in its face
}

TEST(CutSmoothing, ANodeOnAnEdgeSlidesAlongIt) {
  TetMesh mesh = box();
  CutState state = make_cut_state(mesh, {}, {});
  // A node of the box's edge y = z = 0 (its fan: two flat fans at 90 deg), pushed along it.
  const int v = node_at(mesh, Vec3(0.03, 0.0, 0.0));
  mesh.nodes[v].x() += 0.009;
  expect_slides(mesh, state, v, NodeMove::kOnLine, 0, "edge node");
  EXPECT_EQ(mesh.nodes[v].y(), 0.0);  // still on its edge
  EXPECT_EQ(mesh.nodes[v].z(), 0.0);
}

TEST(CutSmoothing, ANodeOnACutThatHasNotOpenedSlidesWithinIt) {
  TetMesh mesh = box();
  CutState state = make_cut_state(mesh, {}, {});
  // An interior node with the faces around it in the plane z = 0.03 marked as a cut that has
  // not opened (both tets' bits, as a held-closed mark leaves them), pushed within the plane.
  const int v = node_at(mesh, Vec3(0.03, 0.03, 0.03));
  const double z = mesh.nodes[v].z();
  int marked = 0;
  for (int t : state.node_tets[v])
    for (int f = 0; f < 4; ++f) {
      const Tet& k = mesh.tets[t];
      if (k[f] == v) continue;
      bool flat = true;
      for (int i = 0; i < 3; ++i) flat = flat && mesh.nodes[k[kTetFaces[f][i]]].z() == z;
      if (!flat || mesh.is_cut_face(t, f)) continue;
      const auto [other, other_face] = neighbour_across(mesh, state, t, f);
      ASSERT_GE(other, 0);
      mesh.cut_faces[t] |= static_cast<std::uint8_t>(1u << f);
      mesh.cut_faces[other] |= static_cast<std::uint8_t>(1u << other_face);
      ++marked;
    }
  ASSERT_GE(marked, 4);  // a fan around v
  mesh.nodes[v] += Vec3(0.009, 0, 0);
  expect_slides(mesh, state, v, NodeMove::kInPlane, 2, "node on a closed cut");
  EXPECT_EQ(mesh.nodes[v].z(), z);  // the marked faces stay in their plane
}

TEST(CutSmoothing, LockedAndCornerNodesStay) {
  TetMesh mesh = box();
  // A corner of the box (three planes meet there: no line keeps it on all) and a locked
  // interior node.
  const int corner = node_at(mesh, Vec3(0.0, 0.0, 0.0));
  const int inner = node_at(mesh, Vec3(0.02, 0.02, 0.02));
  std::vector<std::uint8_t> locked(mesh.nodes.size(), 0);
  locked[inner] = 1;
  CutState state = make_cut_state(mesh, locked, {});
  mesh.nodes[inner] += Vec3(0.008, 0, 0);
  Vec3 axis;
  EXPECT_EQ(how_node_may_move(mesh, state, corner, axis), NodeMove::kNone);
  EXPECT_FALSE(may_move_inside_star(mesh, state, inner));
  const TetMesh before = mesh;
  state.stroke_tets = state.node_tets[corner];
  for (int t : state.node_tets[inner]) state.stroke_tets.push_back(t);
  CutResult r;
  smooth_last_stroke(mesh, state, CutOptions{}, r);
  EXPECT_EQ(mesh.nodes[corner], before.nodes[corner]);
  EXPECT_EQ(mesh.nodes[inner], before.nodes[inner]);
}

// Strokes through the box: the next stroke smooths what the last one left; what opened stays
// open and where it was, the volume is exact, the invariants hold, and fewer tets are thin.
TEST(CutSmoothing, TheNextStrokeSmoothsTheLastOnesTets) {
  int thin[2] = {0, 0};
  for (double smooth : {0.0, 10.0}) {
    TetMesh mesh = box();
    CutState state = make_cut_state(mesh, {}, {});
    const double volume = total_volume(mesh);
    CutOptions options;
    options.smooth_below_deg = smooth;
    // Three oblique strokes, each 4 mm steps (a blade 3 cm long, tilted).
    int thin_after = 0, moved = 0;
    for (int k = 0; k < 3; ++k) {
      const Vec3 tip(0.012 + 0.013 * k, 0.005 + 0.004 * k, 0.0217 + 0.0031 * k);
      const Vec3 along = Vec3(0.3 + 0.2 * k, 1, 0.15).normalized();
      BladeEdge from{tip, tip + 0.03 * Vec3(0.1, -0.2, 1).normalized(), Vec3::UnitX()};
      for (int step = 0; step < 10; ++step) {
        BladeEdge to = from;
        to.tip += 0.004 * along;
        to.heel += 0.004 * along;
        const double open_before = test::open_cut_area(mesh);
        const CutResult r = cut_sweep(mesh, state, from, to, options);
        moved += r.nodes_smoothed;
        if (step == 0 && k > 0 && r.nodes_smoothed > 0) {
          // Smoothing came first; this step's own cut can only add open area.
          EXPECT_GE(test::open_cut_area(mesh), open_before * (1 - 1e-12));
        }
        from = to;
      }
      finish_stroke(mesh, state, options);
      InvariantLimits limits;
      limits.initial_volume = volume;
      std::vector<double> classes = state.origin_volume;
      const auto violated = check_cut_invariants(mesh, classes, limits);
      EXPECT_TRUE(violated.empty()) << "stroke " << k << ": " << violated.front();
    }
    // The last stroke's tets, smoothed as the next stroke would.
    CutResult last;
    const double open = test::open_cut_area(mesh);
    smooth_last_stroke(mesh, state, options, last);
    moved += static_cast<int>(last.moved_nodes.size());
    EXPECT_NEAR(test::open_cut_area(mesh), open, 1e-12 * open);
    EXPECT_NEAR(total_volume(mesh), volume, 1e-12 * volume);
    for (const Tet& e : mesh.tets)
      thin_after += smallest_dihedral_deg(mesh.nodes[e[0]], mesh.nodes[e[1]], mesh.nodes[e[2]],
                                          mesh.nodes[e[3]]) < 10.0;
    std::printf(
        "box, 3 strokes, smoothing below %.0f deg: %d nodes moved, %d tets under 10 deg at "
        "the end, min dihedral %.2f deg\n",
        smooth, moved, thin_after, mesh_quality(mesh).min_dihedral_deg);
    thin[smooth > 0] = thin_after;
    if (smooth == 0) {
      EXPECT_EQ(moved, 0);
    } else {
      EXPECT_GT(moved, 0);
    }
  }
  EXPECT_LT(thin[1], thin[0]);
}

}  // namespace
}  // namespace stc
