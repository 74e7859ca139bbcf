// Simulation::surface_snapshot() + SurfaceSnapshot::compute() (simulation/surface_snapshot.hpp):
// the drawn surface computed from a snapshot equals the model's own recovery of u_S
// (docs/DESIGN.md eq. (13)) to rounding, on the thigh after a press and on the liver after a
// press and a cut; computed later - after the Simulation was reset, cut further, rescaled, or
// on another thread while it steps - it still gives the state the snapshot was taken at. A
// computed snapshot handed back (adopt_recovery) spares the model its own solve.
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

namespace stc {
namespace {

const std::string kLiverCut =
    std::string(TISSUE_TEST_DATA_DIR) + "/../../config/scenes/liver_cut.yaml";

// The surface as Simulation::surface() drew it before snapshots existed: u_N recovered from
// the model's current u_I through its condensed factor (recover_condensed), then rest + u
// per node; the triangles as a snapshot copies them. Leaves the model's recovery cache as it
// was (surface() would fill it).
DeformedSurface reference_surface(const Simulation& sim) {
  const HybridModel& model = sim.model();
  const DisplacementSnapshot d = model.displacement_snapshot();  // the condensed part it holds
  Vector u = model.operation_displacement();
  const CondensedPart& c = *d.condensed;
  if (c.condensed_dofs.rows() > 0)
    scatter(recover_condensed(c, gather(u, c.interface_dofs), d.stiffness_scale), c.condensed_dofs,
            u);
  DeformedSurface s;
  for (int i = 0; i < model.mesh().num_nodes(); ++i) {
    const Vec3 ui = u.segment<3>(3 * i);
    s.positions.push_back(model.mesh().nodes[i] + ui);
    s.displacement.push_back(ui.norm());
  }
  s.triangles = sim.surface_snapshot().triangles;
  return s;
}

// Largest node position difference relative to the largest position; -1 when the node or
// triangle lists differ.
double relative_difference(const DeformedSurface& a, const DeformedSurface& b) {
  if (a.positions.size() != b.positions.size() || a.triangles.size() != b.triangles.size() ||
      a.displacement.size() != b.displacement.size())
    return -1;
  for (size_t t = 0; t < a.triangles.size(); ++t) {
    const BoundaryTriangle &x = a.triangles[t], &y = b.triangles[t];
    if (x.nodes != y.nodes || x.tet != y.tet || x.face != y.face || x.cut != y.cut) return -1;
  }
  double scale = 0, diff = 0;
  for (size_t i = 0; i < a.positions.size(); ++i) {
    scale = std::max(scale, b.positions[i].norm());
    diff = std::max(diff, (a.positions[i] - b.positions[i]).norm());
    diff = std::max(diff, std::abs(a.displacement[i] - b.displacement[i]));
  }
  return diff / scale;
}

// Largest |u| over the nodes: the state is a deformed one.
double largest_displacement(const DeformedSurface& s) {
  return *std::max_element(s.displacement.begin(), s.displacement.end());
}

// The thigh with its scalpel pressing (in contact; cutting off, so later poses press deeper
// instead of cutting): u_I has moved.
void press_thigh(Simulation& sim) {
  sim.set_cutting_enabled(false);
  for (const BladePose& p : sim.scene().trajectory) {
    const StepStats s = sim.step(p);
    if (s.in_contact) return;
  }
  FAIL() << "the thigh's scalpel never pressed";
}

// The liver_cut scene played until its cut has opened (a face is open only once the blade
// has swept all of it: the scene's first, 2-step nick opens nothing on this mesh) and on
// `steps_after_cut` more steps.
void press_and_cut_liver(Simulation& sim, size_t& next_pose, int steps_after_cut) {
  const std::vector<BladePose>& poses = sim.scene().trajectory;
  int after = -1;
  auto opened = [&] {
    for (const BoundaryTriangle& t : extract_boundary_surface(sim.mesh()).triangles)
      if (t.cut) return true;
    return false;
  };
  for (; next_pose < poses.size() && after < steps_after_cut; ++next_pose) {
    sim.step(poses[next_pose]);
    if (after >= 0 || opened()) ++after;
  }
  ASSERT_GT(sim.counts().cuts, 0) << "the liver_cut stroke never cut";
}

TEST(SurfaceSnapshot, ThighPressedEqualsTheModelsRecovery) {
  Simulation sim(make_thigh_scene());
  press_thigh(sim);
  const DeformedSurface reference = reference_surface(sim);
  SurfaceSnapshot snapshot = sim.surface_snapshot();
  EXPECT_TRUE(snapshot.displacement.stale) << "the press moved u_I: u_S must be recovered";
  EXPECT_EQ(snapshot.version, sim.surface_version());
  const double d = relative_difference(snapshot.compute(), reference);
  EXPECT_GE(d, 0) << "node or triangle lists differ";
  EXPECT_LE(d, 1e-15) << d;
  EXPECT_GT(largest_displacement(reference), 1e-4);
  EXPECT_EQ(relative_difference(sim.surface(), reference), d);  // surface(): the same path
}

TEST(SurfaceSnapshot, LiverPressedAndCutEqualsTheModelsRecovery) {
  Simulation sim(load_scene(kLiverCut));
  size_t next = 0;
  press_and_cut_liver(sim, next, 2);
  // On until the surface shows cut faces: a sweep splits tets before any face opens.
  const std::vector<BladePose>& poses = sim.scene().trajectory;
  auto cut_triangles = [](const DeformedSurface& d) {
    int cut = 0;
    for (const BoundaryTriangle& t : d.triangles) cut += t.cut;
    return cut;
  };
  while (next < poses.size() && cut_triangles(reference_surface(sim)) == 0) sim.step(poses[next++]);
  const DeformedSurface reference = reference_surface(sim);
  SurfaceSnapshot snapshot = sim.surface_snapshot();
  const double d = relative_difference(snapshot.compute(), reference);
  EXPECT_GE(d, 0) << "node or triangle lists differ";
  EXPECT_LE(d, 1e-15) << d;
  EXPECT_GT(cut_triangles(reference), 0) << "the snapshot's surface shows the cut";
}

// The snapshot owns what it needs: the Simulation may be reset (its model, factor included,
// destroyed) before the snapshot is computed.
TEST(SurfaceSnapshot, ComputedAfterAResetGivesTheStateAtTheSnapshot) {
  Simulation sim(make_thigh_scene());
  press_thigh(sim);
  const DeformedSurface reference = reference_surface(sim);
  SurfaceSnapshot snapshot = sim.surface_snapshot();
  sim.reset();
  const DeformedSurface now = sim.surface();
  const double moved = relative_difference(now, reference);
  EXPECT_GT(moved, 1e-6) << "the reset state must differ from the pressed one";
  const double d = relative_difference(snapshot.compute(), reference);
  EXPECT_GE(d, 0);
  EXPECT_LE(d, 1e-15) << d;
  // Handed back to the fresh model: ignored (another factor), its surface stays its own.
  sim.adopt_recovery(snapshot);
  EXPECT_EQ(relative_difference(sim.surface(), now), 0.0);
}

TEST(SurfaceSnapshot, ComputedAfterFurtherCutsGivesTheStateAtTheSnapshot) {
  Simulation sim(load_scene(kLiverCut));
  size_t next = 0;
  press_and_cut_liver(sim, next, 1);
  const int nodes_then = sim.mesh().num_nodes();
  const DeformedSurface reference = reference_surface(sim);
  SurfaceSnapshot snapshot = sim.surface_snapshot();
  const std::uint64_t version = snapshot.version;
  press_and_cut_liver(sim, next, 6);  // cuts further: nodes added, tets replaced
  ASSERT_GT(sim.mesh().num_nodes(), nodes_then) << "the stroke did not cut further";
  EXPECT_NE(sim.surface_version(), version);
  const double d = relative_difference(snapshot.compute(), reference);
  EXPECT_GE(d, 0);
  EXPECT_LE(d, 1e-15) << d;
  // Handed back after the cuts (the same factor): the model keeps its own current state.
  const DeformedSurface current = reference_surface(sim);
  sim.adopt_recovery(snapshot);
  const double after = relative_difference(sim.surface(), current);
  EXPECT_GE(after, 0);
  EXPECT_LE(after, 1e-15) << after;
}

// set_young_modulus rescales the condensed part's recovery: a snapshot keeps the scale it was
// taken with, and is not adopted at the new one.
TEST(SurfaceSnapshot, KeepsTheStiffnessItWasTakenAt) {
  Scene scene = make_thigh_scene();
  scene.gravity = Vec3(0, -9.81, 0);  // u_S moves with 1/E even for a fixed u_I
  Simulation sim(scene);
  press_thigh(sim);
  const DeformedSurface reference = reference_surface(sim);
  SurfaceSnapshot snapshot = sim.surface_snapshot();
  sim.set_young_modulus(2 * scene.material.young_modulus);
  const DeformedSurface stiffer = reference_surface(sim);
  EXPECT_GT(relative_difference(stiffer, reference), 1e-6);
  const double d = relative_difference(snapshot.compute(), reference);
  EXPECT_GE(d, 0);
  EXPECT_LE(d, 1e-15) << d;
  sim.adopt_recovery(snapshot);
  const double now = relative_difference(sim.surface(), stiffer);
  EXPECT_GE(now, 0);
  EXPECT_LE(now, 1e-15) << now;
}

// A computed snapshot handed back: the model's S and Q are those, and displacement() (the
// surface, ~save's full displacement) does not solve again until u_I moves.
TEST(SurfaceSnapshot, AdoptedRecoverySparesTheModelASolve) {
  Simulation sim(make_thigh_scene());
  press_thigh(sim);
  SurfaceSnapshot snapshot = sim.surface_snapshot();
  const DeformedSurface computed = snapshot.compute();
  const long recoveries = sim.model().recoveries();
  sim.adopt_recovery(snapshot);
  EXPECT_FALSE(sim.surface_snapshot().displacement.stale);
  EXPECT_EQ(relative_difference(sim.surface(), computed), 0.0);
  const Eigen::VectorXd full = sim.full_displacement();
  EXPECT_EQ((full - snapshot.displacement.u).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(sim.model().recoveries(), recoveries) << "the model solved for u_S again";
  // The blade pressing on: u_I moves, and the model recovers again when asked.
  const auto& poses = sim.scene().trajectory;
  BladePose deeper = poses[1];
  deeper.position = 0.5 * (poses[1].position + poses[2].position);
  ASSERT_GT(sim.step(deeper).cg_iterations, 0);
  EXPECT_TRUE(sim.surface_snapshot().displacement.stale);
  sim.full_displacement();
  EXPECT_EQ(sim.model().recoveries(), recoveries + 1);
}

// The recovery through the shared factor runs on another thread while this one steps and
// recovers through the same factor (surface()): every computation gives the snapshot's state
// bit for bit.
TEST(SurfaceSnapshot, ComputesOnAnotherThreadWhileTheSimulationSteps) {
  Simulation sim(make_thigh_scene());
  press_thigh(sim);
  const DeformedSurface reference = reference_surface(sim);
  const SurfaceSnapshot snapshot = sim.surface_snapshot();
  std::atomic<bool> stop{false};
  std::atomic<int> computed{0}, wrong{0};
  std::thread display([&] {
    while (!stop || computed < 20) {
      SurfaceSnapshot s = snapshot;  // recovers every time
      if (relative_difference(s.compute(), reference) != 0.0) ++wrong;
      ++computed;
    }
  });
  const auto& poses = sim.scene().trajectory;
  for (int k = 1; k <= 20; ++k) {
    BladePose p = poses[1];
    p.position = poses[1].position + (k % 5) * 0.1 * (poses[2].position - poses[1].position);
    sim.step(p);
    sim.surface();
  }
  stop = true;
  display.join();
  EXPECT_EQ(wrong, 0) << "of " << computed << " computations";
}

}  // namespace
}  // namespace stc
