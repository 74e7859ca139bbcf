// The tet grid (cutting/tet_grid.hpp) against a scan of every tet: query() lists exactly the
// included tets whose rest box overlaps the query box, ascending; any() answers whether it
// lists one; grow_by_overlapping() gives the union of their boxes. On the thigh and a TetGen liver,
// with boxes from a point to a few tets across, in and around the tissue, and a grid over part of
// the tets; and the grid a cut state keeps, after strokes that bisect tets, move nodes and flip
// (the grid keeps each tet's box: every change of a tet's corners must reach it).
#include "common/cut_fidelity_scenes.hpp"
#include "cutting/cut_state.hpp"
#include "cutting/tet_grid.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"

#include <gtest/gtest.h>

#include <random>

namespace stc {
namespace {

void expect_grid_matches_scan(const TetMesh& mesh, const TetGrid& grid,
                              const std::vector<std::uint8_t>& include, const char* name) {
  Vec3 lo = mesh.nodes[0], hi = mesh.nodes[0];
  for (const Vec3& p : mesh.nodes) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-0.1, 1.1);  // around the tissue too
  std::uniform_real_distribution<double> size(0.0, 0.05);  // a point to ~5 % of the extent
  int hits = 0, misses = 0;
  for (int q = 0; q < 400; ++q) {
    Vec3 c;
    for (int d = 0; d < 3; ++d) c[d] = lo[d] + unit(rng) * (hi[d] - lo[d]);
    const Vec3 half = Vec3::Constant(size(rng) * (hi - lo).norm());
    const Vec3 a = c - half, b = c + half;
    std::vector<int> scan;
    for (int t = 0; t < mesh.num_tets(); ++t) {
      if (!include[static_cast<size_t>(t)]) continue;
      Vec3 t_lo, t_hi;
      tet_bounds(mesh, t, t_lo, t_hi);
      if ((t_lo.array() <= b.array()).all() && (t_hi.array() >= a.array()).all()) scan.push_back(t);
    }
    const std::vector<int> found = grid.query(mesh, a, b);
    ASSERT_EQ(found, scan) << name << ": query " << q;
    ASSERT_EQ(grid.any(mesh, a, b), !scan.empty()) << name << ": query " << q;
    Vec3 union_lo = a, union_hi = b, grown_lo = a, grown_hi = b;
    for (int t : scan) {
      Vec3 t_lo, t_hi;
      tet_bounds(mesh, t, t_lo, t_hi);
      union_lo = union_lo.cwiseMin(t_lo), union_hi = union_hi.cwiseMax(t_hi);
    }
    grid.grow_by_overlapping(mesh, a, b, grown_lo, grown_hi);
    ASSERT_EQ(grown_lo, union_lo) << name << ": query " << q;
    ASSERT_EQ(grown_hi, union_hi) << name << ": query " << q;
    ++(scan.empty() ? misses : hits);
  }
  // Both answers were exercised.
  EXPECT_GT(hits, 50) << name;
  EXPECT_GT(misses, 20) << name;
}

void expect_grid_matches_scan(const TetMesh& mesh, const char* name) {
  std::vector<std::uint8_t> include(mesh.tets.size());
  for (size_t t = 0; t < include.size(); ++t) include[t] = t % 3 != 0;  // part of the tets
  TetGrid grid;
  grid.build(mesh, include);
  expect_grid_matches_scan(mesh, grid, include, name);
}

TEST(TetGrid, QueryAndAnyMatchAScanOnTheThigh) {
  expect_grid_matches_scan(make_thigh_scene().mesh, "thigh");
}

TEST(TetGrid, QueryAndAnyMatchAScanOnATetGenLiver) {
  expect_grid_matches_scan(fidelity::tetgen_liver("liver2", 5000), "TetGen liver");
}

// Strokes change tets three ways: bisection (a kept child inside its parent's box, appended
// children), node moves (snapping, the smoothing) and flips (new tets on kept indices). The
// grid's kept boxes must follow all of them: its answers equal a scan of the live boxes.
TEST(TetGrid, TheCutStatesGridFollowsStrokes) {
  TetMesh mesh = fidelity::tetgen_liver("liver2", 5000);
  CutState state = make_cut_state(mesh, {}, {});
  const int tets_before = mesh.num_tets();
  const CutResult total = fidelity::crossing_strokes(mesh, state, 4);
  // All three kinds of change happened.
  EXPECT_GT(total.tets_split, 100);
  EXPECT_FALSE(total.moved_nodes.empty());
  EXPECT_GT(total.flips, 0);
  ASSERT_GT(mesh.num_tets(), tets_before);
  expect_grid_matches_scan(mesh, state.grid, state.cuttable, "TetGen liver after 4 strokes");
}

}  // namespace
}  // namespace stc
