// Cut insertion on a structured box: exact areas, volumes and separation (issue 4).
#include "common/cut_measures.hpp"
#include "cutting/cut_state.hpp"
#include "cutting/cut_sweep.hpp"
#include "cutting/free_pieces.hpp"
#include "soft_tissue_cutting/cutting/invariants.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"

#include "common/meshes.hpp"

#include <gtest/gtest.h>

namespace stc {
using test::closed_cut_faces;
using test::open_cut_area;
namespace {

using test::cube_mesh;

// A blade whose edge runs along world +z from the tip and whose normal is world +x: it cuts
// the plane x = const when moved along y.
BladeEdge vertical_edge(double x, double y, double z_tip, double length) {
  BladePose pose;
  pose.position = Vec3(x, y, z_tip);
  Eigen::Matrix3d r;
  r.col(0) = Vec3::UnitZ();  // local x: the edge
  r.col(1) = Vec3::UnitX();  // local y: the blade normal
  r.col(2) = Vec3::UnitY();
  pose.orientation = Eigen::Quaterniond(r);
  return blade_edge(pose, length);
}

void expect_invariants(const TetMesh& mesh, const CutState& state, double v0) {
  InvariantLimits limits;
  limits.initial_volume = v0;
  const auto violated = check_cut_invariants(mesh, state.origin_volume, limits);
  for (const auto& v : violated) ADD_FAILURE() << v;
}

TEST(CutBox, BladeEdgeFollowsPose) {
  const BladeEdge e = vertical_edge(0.025, -0.01, -0.01, 0.06);
  EXPECT_NEAR((e.heel - Vec3(0.025, -0.01, 0.05)).norm(), 0, 1e-15);
  EXPECT_NEAR((e.normal - Vec3::UnitX()).norm(), 0, 1e-15);
}

TEST(CutBox, StraightCutSeparatesWithExactAreaAndVolume) {
  TetMesh mesh = cube_mesh();
  CutState state = make_cut_state(mesh, {}, {});
  const double v0 = total_volume(mesh);
  const CutResult r = cut_sweep(mesh, state, vertical_edge(0.025, -0.01, -0.01, 0.06),
                                vertical_edge(0.025, 0.05, -0.01, 0.06));
  EXPECT_GT(r.tets_split, 0);
  EXPECT_GT(r.nodes_added, 0);
  EXPECT_GT(r.cut_faces_added, 0);
  EXPECT_FALSE(r.reached_interface);
  // Both lips of the 4 cm x 4 cm cut.
  EXPECT_NEAR(open_cut_area(mesh), 2 * 0.04 * 0.04, 1e-9);
  EXPECT_NEAR(total_volume(mesh), v0, 1e-12 * v0);
  EXPECT_EQ(mesh_pieces(mesh).size(), 2u);
  EXPECT_EQ(closed_cut_faces(mesh), 0);
  expect_invariants(mesh, state, v0);
}

TEST(CutBox, CutAlongNodePlaneSplitsNothing) {
  TetMesh mesh = cube_mesh();
  CutState state = make_cut_state(mesh, {}, {});
  const double v0 = total_volume(mesh);
  const int tets0 = mesh.num_tets();
  const CutResult r = cut_sweep(mesh, state, vertical_edge(0.02, -0.01, -0.01, 0.06),
                                vertical_edge(0.02, 0.05, -0.01, 0.06));
  EXPECT_EQ(r.tets_split, 0);
  EXPECT_EQ(mesh.num_tets(), tets0);
  EXPECT_NEAR(open_cut_area(mesh), 2 * 0.04 * 0.04, 1e-9);
  EXPECT_EQ(mesh_pieces(mesh).size(), 2u);
  // 5 x 5 nodes on the plane, all duplicated.
  EXPECT_EQ(r.nodes_added, 25);
  expect_invariants(mesh, state, v0);
}

// A slow stroke through the cube (0.1 mm a step; the cube's front margin is ~3 mm), its band
// a polyline of `points` along the blade: the stroke keeps every band and how many triangles
// each gave, also once the kept list is capped, and the mark phase's thinned list keeps the
// newest and the oldest band and one per spacing between, each dropped band within the
// spacing of a kept one.
void expect_spaced_bands(int points, int steps) {
  TetMesh mesh = cube_mesh();
  CutState state = make_cut_state(mesh, {}, {});
  auto line = [points](double y) {
    std::vector<Vec3> out;
    for (int i = 0; i < points; ++i)
      out.push_back(Vec3(0.0213, y, -0.005 + 0.05 * i / (points - 1)));
    return out;
  };
  const double step = 1e-4;
  for (int k = 0; k < steps; ++k)
    cut_band(mesh, state, line(0.005 + k * step), line(0.005 + (k + 1) * step));
  const auto& stroke = state.last_sweep;
  const std::vector<int>& bands = state.last_sweep_bands;
  long total = 0;
  for (int count : bands) {
    EXPECT_GT(count, 0);
    EXPECT_LE(count, 2 * (points - 1));
    total += count;
  }
  ASSERT_EQ(total, static_cast<long>(stroke.size()));
  EXPECT_LE(stroke.size(), 1024u);
  if (2 * (points - 1) * steps <= 1024) {
    EXPECT_EQ(bands.size(), static_cast<size_t>(steps));
  }

  const double spacing = 1e-3;  // ten steps
  const auto kept = spaced_bands(stroke, bands, spacing);
  // Which bands were kept: `kept` is a subsequence of whole bands.
  std::vector<size_t> first;  // each band's first triangle in `stroke`
  size_t at = 0;
  for (int count : bands) first.push_back(at), at += static_cast<size_t>(count);
  std::vector<size_t> kept_bands;
  size_t next = 0;
  for (size_t b = 0; b < bands.size() && next < kept.size(); ++b)
    if (kept[next][0] == stroke[first[b]][0] && kept[next][1] == stroke[first[b]][1] &&
        kept[next][2] == stroke[first[b]][2]) {
      kept_bands.push_back(b);
      next += static_cast<size_t>(bands[b]);
    }
  ASSERT_EQ(next, kept.size()) << "not a subsequence of whole bands";
  ASSERT_GE(kept_bands.size(), 2u);
  EXPECT_EQ(kept_bands.front(), 0u);
  EXPECT_EQ(kept_bands.back(), bands.size() - 1);
  const double travel = step * static_cast<double>(bands.size() - 1);
  EXPECT_LE(kept_bands.size(), static_cast<size_t>(travel / spacing) + 3);
  EXPECT_GE(kept_bands.size(), static_cast<size_t>(travel / spacing));
  auto apart = [&](size_t a, size_t b) {
    double d = 0;
    for (int v = 0; v < 3; ++v) d = std::max(d, (stroke[first[a]][v] - stroke[first[b]][v]).norm());
    return d;
  };
  for (size_t i = 1; i < kept_bands.size(); ++i)
    for (size_t b = kept_bands[i - 1] + 1; b < kept_bands[i]; ++b)
      EXPECT_LT(apart(b, kept_bands[i]), spacing) << "band " << b << " dropped";
  for (size_t i = 1; i + 1 < kept_bands.size(); ++i)
    EXPECT_GE(apart(kept_bands[i], kept_bands[i + 1]), spacing);
  // Counts that do not describe the list: all of it.
  std::vector<int> wrong = bands;
  wrong.back() += 1;
  EXPECT_EQ(spaced_bands(stroke, wrong, spacing).size(), stroke.size());
  EXPECT_EQ(spaced_bands(stroke, {}, spacing).size(), stroke.size());
}

TEST(CutBox, SlowStrokeKeepsItsBandsAndTheMarkPhaseASpacedSubset) {
  expect_spaced_bands(2, 60);
  // Three segments, six triangles a band: past the 1,024 kept, the oldest band partly dropped.
  expect_spaced_bands(4, 180);
}

}  // namespace
}  // namespace stc

namespace stc {
namespace {

TEST(CutInvariants, CheckerReportsEachKindOfViolation) {
  GeneratorParams g;
  g.size = Vec3(0.02, 0.02, 0.02);
  g.cells = {2, 2, 2};
  TetMesh mesh = make_box_mesh(g);
  CutState state = make_cut_state(mesh, {}, {});
  InvariantLimits limits;
  limits.initial_volume = total_volume(mesh);
  EXPECT_TRUE(check_cut_invariants(mesh, state.origin_volume, limits).empty());

  TetMesh extra_node = mesh;
  extra_node.nodes.push_back(Vec3::Zero());
  EXPECT_EQ(check_cut_invariants(extra_node, state.origin_volume, limits).size(), 1u);

  TetMesh duplicate = mesh;
  duplicate.tets.push_back(mesh.tets[0]);
  duplicate.cut_faces.push_back(0);
  std::vector<double> sizes = state.origin_volume;
  sizes.push_back(sizes[0]);
  // duplicate tet, volume grows, non-manifold faces
  EXPECT_EQ(check_cut_invariants(duplicate, sizes, limits).size(), 3u);

  TetMesh sliver = mesh;  // a node pushed almost into its opposite face
  limits.min_volume_fraction = 0.999;
  sliver.nodes[sliver.tets[0][0]] += Vec3(1e-4, 1e-4, 1e-4);
  EXPECT_GE(check_cut_invariants(sliver, state.origin_volume, limits).size(), 1u);
}

}  // namespace
}  // namespace stc
