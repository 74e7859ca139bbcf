// The mark phase for a stroke's earlier triangles (cutting/earlier_triangles.hpp) marks exactly
// what marking each triangle alone on the tets that overlap it marks (the straightforward
// loop it replaced, kept here as the reference): same faces, same order of marking, same
// interface flag. On the structured cube (whose grid nodes lie exactly on an axis plane: the
// "on a plane, off the stroke" case; and at an interface with the condensed part) and on a
// TetGen liver, with thin sweep-like triangles.
#include "common/cut_fidelity_scenes.hpp"
#include "cutting/earlier_triangles.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <memory>

namespace stc {
namespace {

using Triangles = std::vector<std::array<Vec3, 3>>;

// The reference: every earlier triangle in turn, on the cuttable tets (around the cut) whose
// boxes overlap it; a tet's faces only if three of its corners are on the triangle.
void reference_marks(TetMesh& mesh, const CutState& state, const Triangles& earlier, const Vec3& lo,
                     const Vec3& hi, const CutOptions& options, StrokeSurface& surface,
                     NodeScales& scales, CutResult& result, std::set<FaceKey>& new_faces) {
  Vec3 touched_lo = lo, touched_hi = hi;  // the same tets around the cut
  const std::vector<int> touched = tets_around_cut(mesh, state, touched_lo, touched_hi);
  for (const auto& tri : earlier) {
    TriangleClassification previous(tri[0], tri[1], tri[2], options.snap_tolerance);
    if (previous.degenerate()) continue;
    previous.share_scales(&scales);
    Vec3 a, b;
    previous.bounds(a, b);
    a = a.cwiseMax(touched_lo);
    b = b.cwiseMin(touched_hi);
    if ((a.array() > b.array()).any()) continue;
    for (int t : touched) {
      Vec3 k_lo, k_hi;
      tet_bounds(mesh, t, k_lo, k_hi);
      if (!((k_lo.array() <= b.array()).all() && (a.array() <= k_hi.array()).all())) continue;
      int on = 0;
      for (int v : mesh.tets[t]) on += is_on_stroke(state, v) || previous.side(mesh, state, v) == 0;
      if (on < 3) continue;
      for (int f = 0; f < 4; ++f)
        mark_face_on_triangle(mesh, state, previous, t, f, options, surface, kSkinCornerSlack,
                              result, new_faces);
    }
  }
}

// A slow stroke's sweeps: the edge from `tip` to `heel` moved by `step`, `count` times; two
// thin triangles per sweep.
Triangles sweeps(const Vec3& tip, const Vec3& heel, const Vec3& step, int count) {
  Triangles out;
  for (int k = 0; k < count; ++k) {
    const Vec3 a = tip + k * step, b = heel + k * step, c = tip + (k + 1) * step,
               d = heel + (k + 1) * step;
    out.push_back({a, b, c});
    out.push_back({b, d, c});
  }
  return out;
}

struct Outcome {
  std::vector<std::uint8_t> cut_faces;
  std::set<FaceKey> faces;
  bool reached_interface = false;
  int off_stroke_corners = 0;  // corners of marked faces that are not on the stroke
};

// Splits the mesh along every triangle (as the stroke's sweeps did), then marks the faces on
// them around the box [lo, hi] with `mark`.
using Mark = std::function<void(TetMesh&, const CutState&, const Triangles&, const Vec3&,
                                const Vec3&, const CutOptions&, StrokeSurface&, NodeScales&,
                                CutResult&, std::set<FaceKey>&)>;
Outcome split_then_mark(TetMesh mesh, std::vector<std::uint8_t> cuttable,
                        const Triangles& triangles, const Vec3& lo, const Vec3& hi,
                        const Mark& mark) {
  CutState state = make_cut_state(mesh, {}, std::move(cuttable));
  const CutOptions options;
  CutResult result;
  for (const auto& t : triangles) {
    TriangleClassification c(t[0], t[1], t[2], options.snap_tolerance);
    split_along_triangle(mesh, state, c, options, result);
  }
  StrokeSurface surface(triangles);
  NodeScales scales;
  Outcome out;
  mark(mesh, state, triangles, lo, hi, options, surface, scales, result, out.faces);
  out.cut_faces = mesh.cut_faces;
  out.reached_interface = result.reached_interface;
  for (const FaceKey& key : out.faces)
    for (int v : key) out.off_stroke_corners += !is_on_stroke(state, v);
  return out;
}

void expect_same_marks(const TetMesh& mesh, const std::vector<std::uint8_t>& cuttable,
                       const Triangles& triangles, const Vec3& lo, const Vec3& hi,
                       size_t at_least_faces, bool off_stroke_corners, bool at_interface = false) {
  const Mark fast = [](TetMesh& m, const CutState& s, const Triangles& e, const Vec3& a,
                       const Vec3& b, const CutOptions& o, StrokeSurface& surface,
                       NodeScales& scales, CutResult& r, std::set<FaceKey>& faces) {
    mark_faces_on_earlier_triangles(m, s, e, a, b, o, surface, kSkinCornerSlack, scales, r, faces);
  };
  const Outcome got = split_then_mark(mesh, cuttable, triangles, lo, hi, fast);
  const Outcome want = split_then_mark(mesh, cuttable, triangles, lo, hi, reference_marks);
  EXPECT_EQ(got.faces, want.faces)
      << got.faces.size() << " faces marked, the reference " << want.faces.size();
  EXPECT_TRUE(got.cut_faces == want.cut_faces) << "the tets' face bits differ";
  EXPECT_EQ(got.reached_interface, want.reached_interface);
  // Not vacuous: many faces marked, and (where asked) faces with corners off the stroke that
  // are on the triangles' plane only (the cube's grid nodes).
  EXPECT_GE(want.faces.size(), at_least_faces);
  std::printf("earlier triangles: %zu faces marked (%d corners off the stroke), interface %d\n",
              want.faces.size(), want.off_stroke_corners, int(want.reached_interface));
  if (off_stroke_corners) {
    EXPECT_GT(want.off_stroke_corners, 0);
  }
  EXPECT_EQ(want.reached_interface, at_interface);
}

TetMesh cube() {  // 4 cm, 1 cm cells: grid nodes on the planes z = 0, 0.01, ...
  GeneratorParams g;
  g.size = Vec3(0.04, 0.04, 0.04);
  g.cells = {4, 4, 4};
  return make_box_mesh(g);
}

TEST(EarlierTriangles, MarkWhatEachTriangleAloneMarksOnTheCubeThroughItsGridNodes) {
  // A vertical stroke along x in the grid plane z = 0.02, 0.5 mm a sweep, the cut around
  // all of it.
  const Triangles t =
      sweeps(Vec3(0.003, -0.001, 0.02), Vec3(0.003, 0.027, 0.02), Vec3(0.0005, 0, 0), 60);
  expect_same_marks(cube(), {}, t, Vec3(0.003, 0, 0.019), Vec3(0.033, 0.027, 0.021), 10, true);
}

TEST(EarlierTriangles, MarkWhatEachTriangleAloneMarksOnATiltedCut) {
  // A plane tilted about two axes, through no grid node.
  const Vec3 tip(0.002, -0.001, 0.011), heel(0.002, 0.03, 0.019);
  const Triangles t = sweeps(tip, heel, Vec3(0.0007, 0, 0.0002), 45);
  expect_same_marks(cube(), {}, t, Vec3(0.0, 0, 0.0), Vec3(0.04, 0.03, 0.03), 5, false);
}

TEST(EarlierTriangles, ReportTheInterfaceAsEachTriangleAloneDoes) {
  // The grid-plane stroke with the tets above z = 0.02 condensed (not cuttable): the faces on
  // the plane lie between the two parts, where the blade stops.
  const TetMesh mesh = cube();
  std::vector<std::uint8_t> cuttable(mesh.tets.size(), 1);
  for (int t = 0; t < mesh.num_tets(); ++t) {
    Vec3 c = Vec3::Zero();
    for (int v : mesh.tets[t]) c += mesh.nodes[v] / 4.0;
    cuttable[t] = c.z() < 0.02;
  }
  const Triangles t =
      sweeps(Vec3(0.003, -0.001, 0.02), Vec3(0.003, 0.027, 0.02), Vec3(0.0005, 0, 0), 60);
  expect_same_marks(mesh, cuttable, t, Vec3(0.003, 0, 0.019), Vec3(0.033, 0.027, 0.021), 0, false,
                    true);
}

TEST(EarlierTriangles, MarkWhatEachTriangleAloneMarksOnATetGenLiver) {
  // The ~5k-tet TetGen liver (15 cm): a tilted blade drawn 6 cm through its middle,
  // 0.4 mm a sweep, the cut around the last 2 cm.
  const TetMesh mesh = fidelity::tetgen_liver("liver2", 5000);
  Vec3 lo = mesh.nodes[0], hi = lo;
  for (const Vec3& x : mesh.nodes) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  const Vec3 mid = (lo + hi) / 2;
  const Vec3 tip = mid + Vec3(-0.04, -0.02, -0.004), heel = mid + Vec3(-0.04, 0.02, 0.006);
  const Triangles t = sweeps(tip, heel, Vec3(0.0004, 0, 0.0001), 150);
  const Vec3 end = tip + 150 * Vec3(0.0004, 0, 0.0001);
  expect_same_marks(mesh, {}, t, end - Vec3(0.02, 0, 0.01), end + Vec3(0, 0.04, 0.02), 30, false);
}

// A face's corner test (StrokeSurface::corner_near): within the slack of the stroke's surface,
// or on the tissue's boundary within skin_slack x the slack - what it finds out once per node
// must not change the answer for another slack. Every node of the cube (its boundary is where
// a coordinate is 0 or 4 cm) against a plane 0.1 mm above its middle layer, slacks asked in
// an order that grows and shrinks, twice.
TEST(EarlierTriangles, CornerTestIsNearOrOnTheSkinAndNearerAtEveryAskedSlack) {
  TetMesh mesh = cube();
  const CutState state = make_cut_state(mesh, {}, {});
  const double z = 0.0201;
  StrokeSurface surface({{Vec3(-0.01, -0.01, z), Vec3(0.05, -0.01, z), Vec3(0.05, 0.05, z)},
                         {Vec3(-0.01, -0.01, z), Vec3(0.05, 0.05, z), Vec3(-0.01, 0.05, z)}});
  int skin_only = 0, near = 0;
  for (int pass = 0; pass < 2; ++pass)
    for (double slack : {2e-4, 3e-5, 1e-4, 5e-5, 1e-3, 2e-5}) {
      for (int v = 0; v < mesh.num_nodes(); ++v) {
        const Vec3& x = mesh.nodes[v];
        const bool skin = (x.array() < 1e-9).any() || (x.array() > 0.04 - 1e-9).any();
        const double d = std::abs(x.z() - z);
        const bool expected = d <= slack || (skin && d <= kSkinCornerSlack * slack);
        ASSERT_EQ(surface.corner_near(mesh, state, v, slack, kSkinCornerSlack), expected)
            << "node " << v << " at " << x.transpose() << ", slack " << slack;
        skin_only += expected && d > slack;
        near += expected;
      }
    }
  // Both reasons occurred (the middle layer's skin nodes at 3e-5 and 5e-5).
  EXPECT_GT(skin_only, 0);
  EXPECT_GT(near, skin_only);
}

// The limit ahead of the blade (StrokeSurface::add_limit, CutOptions::front_corner_reach): a
// corner near the surface is refused when it lies farther ahead of the blade's edge, along its
// motion, than the reach plus slack_fraction x its slack - skin corners too - and the rest is
// answered as without the limit. The cube's nodes against its plane z = 0.02 (a grid plane),
// the blade's edge along y at x = 0.0185 moving along +x, reach 1 mm, a quarter of the slack:
// the grid nodes at x = 0.02 (1.5 mm ahead) pass at a slack of 2.5 or 4 mm, not at 0.1 mm; those
// at x = 0.03 and 0.04 never do.
TEST(EarlierTriangles, CornerTestStopsAheadOfTheBlade) {
  TetMesh mesh = cube();
  const CutState state = make_cut_state(mesh, {}, {});
  const double z = 0.02, edge_x = 0.0185, reach = 1e-3, fraction = 0.25;
  const Triangles plane = {{Vec3(-0.01, -0.01, z), Vec3(0.05, -0.01, z), Vec3(0.05, 0.05, z)},
                           {Vec3(-0.01, -0.01, z), Vec3(0.05, 0.05, z), Vec3(-0.01, 0.05, z)}};
  StrokeSurface limited(plane), unlimited(plane);
  limited.add_limit({Vec3(edge_x, -0.01, z), Vec3(edge_x, 0.05, z)}, {Vec3::UnitX(), Vec3::UnitX()},
                    reach, fraction);
  int refused = 0, kept_ahead = 0;
  for (const double slack : {1e-4, 4e-3, 2.5e-3}) {
    for (int v = 0; v < mesh.num_nodes(); ++v) {
      const Vec3& x = mesh.nodes[v];
      const bool without = unlimited.corner_near(mesh, state, v, slack, kSkinCornerSlack);
      const double ahead = x.x() - edge_x;
      const bool expected = without && ahead <= reach + fraction * slack;
      ASSERT_EQ(limited.corner_near(mesh, state, v, slack, kSkinCornerSlack), expected)
          << "node " << v << " at " << x.transpose() << ", slack " << slack;
      refused += without && !expected;
      kept_ahead += expected && ahead > 0;
    }
  }
  EXPECT_GT(refused, 0);
  EXPECT_GT(kept_ahead, 0);
}

// A face refused only by a limit (it lies past where the blade is) is kept (StrokeSurface::
// defer) and marked once the blade has moved on (mark_deferred_faces); until then it waits, and
// a face that no longer exists is dropped. The cube's faces in its grid plane z = 0.02 against
// that plane, the blade's edge along y moving along +x: at x = 0.0005 every face there with a
// corner at x >= 0.01 is refused; with the edge at x = 0.045 none is.
TEST(EarlierTriangles, FacesPastTheBladeAreMarkedOnceItHasPassed) {
  TetMesh mesh = cube();
  const CutState state = make_cut_state(mesh, {}, {});
  const double z = 0.02;
  const Triangles plane = {{Vec3(-0.01, -0.01, z), Vec3(0.05, -0.01, z), Vec3(0.05, 0.05, z)},
                           {Vec3(-0.01, -0.01, z), Vec3(0.05, 0.05, z), Vec3(-0.01, 0.05, z)}};
  const CutOptions options;
  auto edge_at = [&](double x) {
    auto surface = std::make_unique<StrokeSurface>(plane);
    surface->add_limit({Vec3(x, -0.01, z), Vec3(x, 0.05, z)}, {Vec3::UnitX(), Vec3::UnitX()}, 0,
                       0.25);
    return surface;
  };
  // The blade at x = 0.0005: nothing in the plane is marked, its faces wait.
  const auto short_of_them = edge_at(0.0005);
  CutResult result;
  std::set<FaceKey> marked;
  for (const auto& t : plane) {
    TriangleClassification tri(t[0], t[1], t[2], options.snap_tolerance);
    mark_faces_on_triangle(mesh, state, tri, Vec3(-0.01, -0.01, z - 1e-3),
                           Vec3(0.05, 0.05, z + 1e-3), options, *short_of_them, kSkinCornerSlack,
                           result, marked);
  }
  std::vector<FaceKey> waiting = short_of_them->deferred();
  std::sort(waiting.begin(), waiting.end());
  waiting.erase(std::unique(waiting.begin(), waiting.end()), waiting.end());
  // 4 x 4 cells in the plane, two triangles each, every one with a corner at x >= 0.01.
  EXPECT_TRUE(marked.empty());
  ASSERT_EQ(waiting.size(), 32u);
  for (const FaceKey& key : waiting)
    for (int v : key) EXPECT_NEAR(mesh.nodes[v].z(), z, 1e-12);
  // The blade not moved yet: they still wait, nothing is marked.
  std::set<FaceKey> none;
  EXPECT_EQ(mark_deferred_faces(mesh, state, waiting, *edge_at(0.0005), kSkinCornerSlack, none),
            waiting);
  EXPECT_TRUE(none.empty());
  // The blade past them all: every one is marked, on both of its sides.
  const long before = std::count_if(mesh.cut_faces.begin(), mesh.cut_faces.end(),
                                    [](std::uint8_t bits) { return bits != 0; });
  std::set<FaceKey> now;
  EXPECT_TRUE(
      mark_deferred_faces(mesh, state, waiting, *edge_at(0.045), kSkinCornerSlack, now).empty());
  EXPECT_EQ(now.size(), waiting.size());
  long sides = 0;
  for (std::uint8_t bits : mesh.cut_faces)
    for (int f = 0; f < 4; ++f) sides += (bits >> f) & 1;
  EXPECT_EQ(sides, 2 * static_cast<long>(waiting.size()));
  EXPECT_EQ(before, 0);
  // Marked already, or no longer a face of the mesh: dropped.
  std::vector<FaceKey> gone = waiting;
  gone.push_back({0, 1, 2});                     // not a face of the cube's tets
  gone.push_back({0, 1, mesh.num_nodes() + 5});  // not a node (a stale key): no crash
  std::set<FaceKey> again;
  EXPECT_TRUE(
      mark_deferred_faces(mesh, state, gone, *edge_at(0.0005), kSkinCornerSlack, again).empty());
  EXPECT_TRUE(again.empty());
}

}  // namespace
}  // namespace stc
