// A replayed stroke cuts what its poses say, not how they arrived (docs/DESIGN.md section 7):
// - a blade held still changes nothing: every trajectory played with one step per pose and
//   again with each pose held for one to four steps ends in the same mesh (mesh_hash), the same
//   cut counts and the same displacement; a repeated step cuts nothing and runs no CG
//   iteration. The ROS node samples the latest pose on its own clock, so this is what makes a
//   lockstep bag replay end in the same mesh on a loaded machine as on an idle one
//   (test/ros/rostest_bag_replay.cpp);
// - the poses' last digits decide nothing: the same trajectory with every coordinate and
//   quaternion component moved by up to 1e-16 (what composing tf transforms does to a robot's
//   tool frame, test/ros/rostest_tf_scalpel.cpp) cuts the same tets and opens the same area.
// On the built-in thigh (its stroke resampled every 1 or 2 mm), the TetGen liver_cut scene (a
// sagging TetGen liver) and thigh_follow (the moving region, offline: every move awaited).
#include "common/cut_measures.hpp"
#include "soft_tissue_cutting/cutting/blade_path.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>

namespace stc {
namespace {

std::string scene_path(const char* name) {
  return std::string(TISSUE_TEST_DATA_DIR) + "/../../config/scenes/" + name;
}

struct Played {
  std::string hash;
  ModelCounts counts;
  Eigen::VectorXd u;
  int cut_steps = 0;
  int repeated_steps = 0;
  int finishes_held = 0;  // strokes finished on a held step
  double opened = 0;      // m^2, one side of the open cut faces
};

// Plays the scene's trajectory, pose k held for hold(k) steps, then one step without blade.
template <typename Hold>
Played play(const Scene& scene, Hold hold, const char* what) {
  SimulationOptions options;
  options.wait_for_region_moves = true;  // offline: a `follow` move is awaited (deterministic)
  options.wait_for_factor_ahead = true;  // and a factor refactored ahead
  Simulation sim(scene, options);
  Played out;
  for (size_t k = 0; k < scene.trajectory.size(); ++k) {
    for (int r = 0; r < hold(k); ++r) {
      const StepStats s = sim.step(scene.trajectory[k]);
      EXPECT_TRUE(s.converged) << what << ": pose " << k;
      out.cut_steps += s.cutting;
      if (r == 0) continue;
      ++out.repeated_steps;
      // The end of a stroke is conformed and opened on the step after the blade's last cut
      // (one model update per step), whether that step moves the blade or holds it: the same
      // cut, on another step.
      if (s.stroke_finished) {
        ++out.finishes_held;
        continue;
      }
      EXPECT_FALSE(s.cutting) << what << ": pose " << k << " held, step " << r << " cut";
      EXPECT_EQ(s.tets_split, 0) << what << ": pose " << k;
      EXPECT_EQ(s.cg_iterations, 0) << what << ": pose " << k << " held, step " << r;
    }
  }
  sim.step(std::nullopt);
  out.hash = sim.mesh_hash();
  out.opened = 0.5 * test::open_cut_area(sim.mesh());
  out.counts = sim.counts();
  out.u = sim.full_displacement();
  return out;
}

void held_poses_change_nothing(const Scene& scene, const char* what) {
  ASSERT_GT(scene.trajectory.size(), 20u) << what;
  const Played once = play(
      scene, [](size_t) { return 1; }, what);
  // 1..4 steps per pose, varied so that the yield, the first cutting sweep and the lift-out
  // each fall on held and on single poses somewhere.
  const Played held = play(
      scene, [](size_t k) { return 1 + static_cast<int>((k * 7 + 3) % 4); }, what);
  EXPECT_GT(once.counts.cuts, 0) << what << ": the trajectory must cut";
  EXPECT_GT(held.repeated_steps, static_cast<int>(scene.trajectory.size())) << what;
  EXPECT_EQ(once.hash, held.hash) << what;
  EXPECT_EQ(once.counts.tets, held.counts.tets) << what;
  EXPECT_EQ(once.counts.nodes, held.counts.nodes) << what;
  EXPECT_EQ(once.counts.cuts, held.counts.cuts) << what;
  // A stroke's end finished on a held step is a step of its own; moving on, it may share the
  // next stroke's first step.
  EXPECT_LE(once.cut_steps, held.cut_steps) << what;
  EXPECT_LE(held.cut_steps, once.cut_steps + held.finishes_held) << what;
  ASSERT_EQ(once.u.size(), held.u.size()) << what;
  const double scale = once.u.cwiseAbs().maxCoeff();
  EXPECT_GT(scale, 1e-4) << what << ": the tissue must deform";
  EXPECT_LE((once.u - held.u).cwiseAbs().maxCoeff(), 1e-12 * scale) << what;
  std::printf("%s: %zu poses, %d held steps, %d cutting steps, %d tets, hash %s in both\n", what,
              scene.trajectory.size(), held.repeated_steps, once.cut_steps, once.counts.tets,
              once.hash.c_str());
}

void rounding_decides_nothing(const Scene& scene, const char* what) {
  const Played exact = play(
      scene, [](size_t) { return 1; }, what);
  EXPECT_GT(exact.counts.cuts, 0) << what << ": the trajectory must cut";
  for (unsigned seed : {1u, 2u, 3u}) {
    Scene moved = scene;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> e(-1e-16, 1e-16);
    for (BladePose& p : moved.trajectory) {
      p.position += Vec3(e(rng), e(rng), e(rng));
      p.orientation.coeffs() += Eigen::Vector4d(e(rng), e(rng), e(rng), e(rng));
    }
    const Played r = play(
        moved, [](size_t) { return 1; }, what);
    EXPECT_EQ(exact.counts.cuts, r.counts.cuts) << what << ", seed " << seed;
    EXPECT_EQ(exact.counts.tets_split, r.counts.tets_split) << what << ", seed " << seed;
    EXPECT_EQ(exact.counts.tets, r.counts.tets) << what << ", seed " << seed;
    EXPECT_EQ(exact.counts.nodes, r.counts.nodes) << what << ", seed " << seed;
    EXPECT_NEAR(exact.opened, r.opened, 1e-9 * exact.opened + 1e-15) << what << ", seed " << seed;
  }
  std::printf(
      "%s: %zu poses moved by up to 1e-16, 3 times: %d cuts, %d tets, %.1f mm^2 opened in "
      "each\n",
      what, scene.trajectory.size(), exact.counts.cuts, exact.counts.tets, exact.opened * 1e6);
}

// The built-in thigh's six waypoints, a pose every `spacing` of travel (the recorded bag of
// test/ros/rostest_bag_replay.cpp samples the same stroke about every mm).
Scene thigh_every(double spacing) {
  Scene thigh = make_thigh_scene();
  thigh.trajectory = resample_blade_path(thigh.trajectory, thigh.scalpel.blade_length, spacing);
  return thigh;
}

TEST(SimulationReplay, HeldPosesChangeNothingOnTheThigh) {
  held_poses_change_nothing(thigh_every(2e-3), "thigh");
}

TEST(SimulationReplay, HeldPosesChangeNothingOnTheTetGenLiver) {
  held_poses_change_nothing(load_scene(scene_path("liver_cut.yaml")), "liver_cut");
}

TEST(SimulationReplay, HeldPosesChangeNothingWithAMovingRegion) {
  held_poses_change_nothing(load_scene(scene_path("thigh_follow.yaml")), "thigh_follow");
}

TEST(SimulationReplay, RoundingOfThePosesDecidesNothingOnTheThigh) {
  rounding_decides_nothing(thigh_every(1e-3), "thigh");
}

TEST(SimulationReplay, RoundingOfThePosesDecidesNothingOnTheTetGenLiver) {
  rounding_decides_nothing(load_scene(scene_path("liver_cut.yaml")), "liver_cut");
}

// thigh_follow's stroke advances exactly 0.1 R per pose, the follow region's smallest move:
// whether the region moved (and so the cut, which waits at the interface for a move) was
// decided by the poses' last digits (region_follower.cpp, worth_moving_to).
TEST(SimulationReplay, RoundingOfThePosesDecidesNothingWithAMovingRegion) {
  rounding_decides_nothing(load_scene(scene_path("thigh_follow.yaml")), "thigh_follow");
}

}  // namespace
}  // namespace stc
