// Flips after a stroke (cutting/tet_flips.hpp, docs/DESIGN.md section 8 "Flip"): a cap resting
// on a tall tet becomes three tets around the edge through it; a face on a cut is never flipped;
// on a TetGen liver after six strokes, both kinds of flip are made and change no boundary face,
// no cut face and no volume, while the tets under 5 deg become fewer.
#include "common/cut_fidelity_scenes.hpp"
#include "common/cut_measures.hpp"
#include "common/cut_state_checks.hpp"
#include "cutting/cut_state.hpp"
#include "cutting/cut_sweep.hpp"
#include "cutting/tet_flips.hpp"
#include "soft_tissue_cutting/cutting/invariants.hpp"
#include "soft_tissue_cutting/mesh/boundary_surface.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

namespace stc {
namespace {

double smallest_angle(const TetMesh& mesh) { return mesh_quality(mesh).min_dihedral_deg; }

// The boundary's faces and the faces on a cut, each as its sorted corners (a face on a cut
// that has not opened is listed once per side).
std::multiset<std::array<int, 3>> faces_that_stay(const TetMesh& mesh) {
  std::multiset<std::array<int, 3>> faces;
  for (const BoundaryTriangle& t : extract_boundary_surface(mesh).triangles) {
    std::array<int, 3> k = {t.nodes[0], t.nodes[1], t.nodes[2]};
    std::sort(k.begin(), k.end());
    faces.insert(k);
  }
  for (int t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f)
      if (mesh.is_cut_face(t, f)) {
        const Tet& e = mesh.tets[static_cast<size_t>(t)];
        std::array<int, 3> k = {e[kTetFaces[f][0]], e[kTetFaces[f][1]], e[kTetFaces[f][2]]};
        std::sort(k.begin(), k.end());
        k[0] = -1 - k[0];  // negative first corner: a cut side, not a boundary face
        faces.insert(k);
      }
  return faces;
}

// A cap (apex 0.05 over an equilateral face of circumradius 1: 5.7 deg at its base edges) on a
// tall tet (apex 1.5 below).
TetMesh cap_on_tall_tet() {
  TetMesh mesh;
  mesh.nodes = {Vec3(1, 0, 0), Vec3(-0.5, 0.8660254, 0), Vec3(-0.5, -0.8660254, 0),
                Vec3(0, 0, 0.05), Vec3(0, 0, -1.5)};
  mesh.tets = {Tet{0, 1, 2, 3}, Tet{0, 2, 1, 4}};
  return mesh;
}

TEST(TetFlips, ACapAndTheTetBelowItBecomeThreeTets) {
  TetMesh mesh = cap_on_tall_tet();
  CutState state = make_cut_state(mesh, {}, {});
  const double volume = total_volume(mesh), before = smallest_angle(mesh);
  const auto surface = faces_that_stay(mesh);
  CutResult result;
  const FlipCounts flips = flip_thin_tets(mesh, state, CutOptions{}, {0, 1}, result);
  EXPECT_EQ(flips.faces, 1);
  EXPECT_EQ(flips.edges, 0);
  ASSERT_EQ(mesh.num_tets(), 3);
  EXPECT_EQ(result.changed_tets, (std::vector<int>{0, 1, 2}));
  for (const Tet& e : mesh.tets) {  // each holds the new edge (3, 4)
    EXPECT_NE(std::find(e.begin(), e.end(), 3), e.end());
    EXPECT_NE(std::find(e.begin(), e.end(), 4), e.end());
  }
  EXPECT_NEAR(total_volume(mesh), volume, 1e-15);
  EXPECT_EQ(faces_that_stay(mesh), surface);
  EXPECT_GT(smallest_angle(mesh), before + 10.0) << "from " << before << " deg";
  InvariantLimits limits;
  limits.initial_volume = volume;
  EXPECT_TRUE(check_cut_invariants(mesh, state.origin_volume, limits).empty());
  for (int v = 0; v < 5; ++v)
    EXPECT_EQ(state.node_tets[static_cast<size_t>(v)].size(), v < 3 ? 2u : 3u);
}

TEST(TetFlips, AFaceOnACutIsNotFlipped) {
  TetMesh mesh = cap_on_tall_tet();
  CutState state = make_cut_state(mesh, {}, {});
  mesh.cut_faces[0] |= 1u << 3;  // face (0, 1, 2): opposite corner 3 of tet 0
  mesh.cut_faces[1] |= 1u << 3;  // and opposite corner 4 of tet 1
  const TetMesh before = mesh;
  CutResult result;
  EXPECT_EQ(flip_thin_tets(mesh, state, CutOptions{}, {0, 1}, result).total(), 0);
  EXPECT_EQ(mesh.tets, before.tets);
  EXPECT_TRUE(result.changed_tets.empty());
}

TEST(TetFlips, AfterStrokesOnATetGenLiverOnlyTheInsideChanges) {
  TetMesh mesh = fidelity::tetgen_liver("liver2", 5000);
  CutState state = make_cut_state(mesh, {}, {});
  const double volume = total_volume(mesh);
  CutOptions options;
  options.flip_thin_tets = false;  // the strokes smooth but do not flip
  fidelity::crossing_strokes(mesh, state, 6, options);
  const auto stay = faces_that_stay(mesh);
  const int thin_before = test::thin_tets(mesh), tets_before = mesh.num_tets();
  std::vector<int> all(static_cast<size_t>(mesh.num_tets()));
  for (int t = 0; t < mesh.num_tets(); ++t) all[static_cast<size_t>(t)] = t;
  CutResult result;
  const FlipCounts flips = flip_thin_tets(mesh, state, CutOptions{}, all, result);
  const int thin_after = test::thin_tets(mesh);
  std::printf(
      "TetGen liver, 6 strokes: %d 2-3 flips, %d edge removals; tets %d -> %d, under 5 deg "
      "%d -> %d\n",
      flips.faces, flips.edges, tets_before, mesh.num_tets(), thin_before, thin_after);
  EXPECT_GT(flips.faces, 0);
  EXPECT_GT(flips.edges, 0);
  EXPECT_LT(thin_after, thin_before);
  EXPECT_EQ(faces_that_stay(mesh), stay) << "a boundary or cut face changed";
  EXPECT_NEAR(total_volume(mesh), volume, 1e-12 * volume);
  InvariantLimits limits;
  limits.initial_volume = volume;
  const auto violated = check_cut_invariants(mesh, state.origin_volume, limits);
  EXPECT_TRUE(violated.empty()) << violated.front();
  // The cut state follows: every tet in its corners' stars, and only there.
  EXPECT_EQ(test::stars_mismatch(mesh, state), "");
  EXPECT_EQ(state.cuttable.size(), mesh.tets.size());
}

}  // namespace
}  // namespace stc
