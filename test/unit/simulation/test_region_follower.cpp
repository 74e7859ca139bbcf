// The operation region that follows the scalpel (`operation_region: {follow: {radius}}`):
// re-partitioning is exact (the moved model solves the same loads and contacts to the same
// displacement, cut tets condensed with the rest), and a 10 cm stroke across the thigh and a
// TetGen liver, crossing several region moves, cuts continuously, keeps docs/SCENE.md "Cut
// invariants" after every step and equals the full model at the end.
#include "common/follow_stroke.hpp"
#include "common/free_piece_log.hpp"

#include "collision/tissue_samples.hpp"
#include "cutting/free_pieces.hpp"
#include "simulation/region_follower.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/partition/follow_region.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/simulation/operation_surface.hpp"

#include "common/mesh_files.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <sstream>

namespace stc {
namespace {

// The scene key: a radius > 0 and finite, one clear line otherwise; the ball starts at the
// first trajectory pose's tip (else the centre of the mesh's bounding box).
TEST(FollowRegion, SceneKeyParsedWithClearErrors) {
  test::TempDir dir;
  const std::string head =
      "mesh: {generator: {type: box, size: [0.1, 0.02, 0.02], cells: [10, 2, 2]}}\n"
      "fixed: [{box: {min: [-1, -1, -1], max: [0.001, 1, 1]}}]\n";
  const Scene ok = load_scene(test::write_file(
      dir.file("ok.yaml"), head + "operation_region: {follow: {radius: 0.03}}\n"
                                  "trajectory: [{t: 0, position: [0.05, 0.03, 0.01]}]\n"));
  EXPECT_TRUE(ok.operation_region.follows_blade());
  EXPECT_DOUBLE_EQ(ok.operation_region.sphere.radius, 0.03);
  EXPECT_LT((ok.operation_region.sphere.center - Vec3(0.05, 0.03, 0.01)).norm(), 1e-15);
  const Scene no_traj = load_scene(
      test::write_file(dir.file("nt.yaml"), head + "operation_region: {follow: {radius: 0.03}}\n"));
  EXPECT_LT((no_traj.operation_region.sphere.center - Vec3(0.05, 0.01, 0.01)).norm(), 1e-12);
  auto error = [&](const std::string& region) {
    try {
      load_scene(
          test::write_file(dir.file("bad.yaml"), head + "operation_region: " + region + "\n"));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("loaded");
  };
  EXPECT_NE(error("{follow: {radius: 0}}").find("operation_region.follow.radius: must be > 0"),
            std::string::npos);
  EXPECT_NE(error("{follow: {radius: -1}}").find("must be > 0"), std::string::npos);
  EXPECT_NE(error("{follow: {radius: .inf}}").find("finite"), std::string::npos);
  EXPECT_NE(error("{follow: {radius: .nan}}").find("finite"), std::string::npos);
  EXPECT_NE(error("{follow: {}}").find("operation_region.follow.radius: missing"),
            std::string::npos);
  EXPECT_NE(error("{follow: {radius: 0.02, centre: [0, 0, 0]}}").find("unknown key"),
            std::string::npos);
  EXPECT_NE(error("{follow: 0.02}").find("operation_region.follow"), std::string::npos);
  EXPECT_NE(
      error("{follow: {radius: 0.02}, sphere: {center: [0, 0, 0], radius: 1}}").find("exactly one"),
      std::string::npos);
}

// A follow scene runs offline like `tissue solve` does and reports its moves.
TEST(FollowRegion, FollowSceneRunsAndReportsMoves) {
  Scene scene = make_thigh_scene();
  scene.operation_region.kind = OperationRegion::Kind::kFollow;
  scene.operation_region.sphere.radius = 0.02;
  SimulationOptions offline;
  offline.wait_for_region_moves = true;
  offline.wait_for_factor_ahead = true;
  Simulation sim(scene, offline);
  ASSERT_NE(sim.region_moves(), nullptr);
  // Press on the outer wall away from the initial ball: the region comes to the blade.
  const Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  std::vector<BladePose> poses;
  const Vec3 far(0.06 * std::cos(1.2), 0.06 * std::sin(1.2), 0.03);
  const Vec3 out = far * (0.07 / 0.06);
  test::append_line(poses, out, far * (0.055 / 0.06), 10, q);
  for (const BladePose& p : poses) EXPECT_TRUE(sim.step(p).converged);
  sim.step(std::nullopt);
  EXPECT_GE(sim.region_moves()->moves, 1);
  EXPECT_LT((sim.region_moves()->ball.center - far).norm(), 0.02);
  const std::string json = sim.stats_json(0);
  EXPECT_NE(json.find("\"region_moves\""), std::string::npos);
  EXPECT_LT(test::relative_error_vs_full_model(sim), 1e-8);
}

double max_abs_diff(const Vector& a, const Vector& b) { return (a - b).cwiseAbs().maxCoeff(); }

// Re-partitioning a cut thigh so that its cut falls in the condensed part changes no
// displacement: same loads, same imposed (contact) displacements, same solution.
TEST(FollowRegion, RepartitionedModelSolvesTheSameWithCutGeometryCondensed) {
  Scene scene = make_thigh_scene();
  scene.solver.tolerance = 1e-13;
  Simulation sim(scene);
  // One incision through the operation part (the scene's own stroke: press, draw, lift).
  BladePose a, b;
  a.position = Vec3(0.048, 0.003, 0.03);
  b.position = Vec3(0.048, 0.003, 0.066);
  const CutOutcome cut = sim.cut_along({a, b});
  ASSERT_TRUE(cut.success) << cut.message;
  const HybridModel& old_model = sim.model();
  // Imposed displacements on three operation nodes far from the cut (a blade pressing there).
  std::vector<int> pressed;
  for (int n : old_model.partition().operation)
    if ((old_model.mesh().nodes[n] - Vec3(0.06 * std::cos(0.6), 0.06 * std::sin(0.6), 0.048))
            .norm() < 0.012)
      pressed.push_back(n);
  ASSERT_GE(pressed.size(), 3u);
  pressed.resize(3);
  // The new ball holds the pressed nodes but not the cut (centre ~35 degrees round the tube).
  const Sphere ball{Vec3(0.06 * std::cos(0.9), 0.06 * std::sin(0.9), 0.048), 0.03};
  HybridModel moved(old_model, follow_region_labels(old_model.mesh(), ball, pressed));
  moved.set_cg_settings(old_model.cg_settings());
  int cut_tets_condensed = 0;
  for (int t : moved.partition().condensed_tets)
    cut_tets_condensed += moved.mesh().cut_faces[t] != 0;
  EXPECT_GT(cut_tets_condensed, 10) << "the cut must lie in the new condensed part";
  for (int n : pressed) {
    const NodeSet set = moved.partition().node_set[n];
    ASSERT_TRUE(set == NodeSet::kOperation || set == NodeSet::kInterface);
  }

  ImposedDisplacements contact;
  for (int n : pressed) contact[n] = Vec3(-0.002, 0.0005, 0.0);
  HybridModel reference(old_model, old_model.partition().operation_tet);  // the old partition
  reference.set_cg_settings(old_model.cg_settings());
  ASSERT_TRUE(reference.solve(contact).converged);
  moved.set_displacement(old_model.displacement());  // the swap hands the state over
  ASSERT_TRUE(moved.solve(contact).converged);
  reference.recover_interior();
  moved.recover_interior();
  const double scale = reference.displacement().cwiseAbs().maxCoeff();
  EXPECT_LT(max_abs_diff(moved.displacement(), reference.displacement()), 1e-9 * scale);
  // And the reaction on the pressed nodes (the blade's wrench) is the same.
  EXPECT_LT((moved.reaction_force(pressed) - reference.reaction_force(pressed)).norm(),
            1e-8 * reference.reaction_force(pressed).norm());
}

// The refined thigh (resolution 0.7) of the follow-region stroke tests, a 2.5 cm follow ball.
const char* const kThighFollowYaml =
    "mesh: {generator: {type: thigh, length: 0.14, resolution: 0.7}}\n"
    "fixed: [{box: {min: [-0.0151, -0.0151, -0.001], max: [0.0151, 0.0151, 0.141]}}]\n"
    "operation_region: {follow: {radius: 0.025}}\n"
    "gravity: [0, -9.81, 0]\n"
    "scalpel: {blade_length: 0.02, cut_pressure: 0.3}\n"
    "trajectory: [{t: 0, position: [0.065, 0.003, 0.02]}]\n"
    "solver: {tolerance: 1.0e-12}\n";

// A ~cut path that starts outside the follow ball (the ROS node's ~cut, whose caller knows
// nothing of the region): the region moves to each sweep before it is cut, and the path is
// carried to rest coordinates through the deformation of the whole tissue, not through the
// part 1 the ball held when the path was begun (there the path meets no tet: before the fix
// it cut nothing, "the blade path does not cross the operation part"). Opened faces along every
// centimetre of the path.
TEST(FollowRegion, CutPathStartingOutsideTheBallCutsEndToEnd) {
  test::TempDir dir;
  const Scene scene = load_scene(test::write_file(dir.file("s.yaml"), kThighFollowYaml));
  Simulation sim(scene);  // online, as tissue_node runs it: cut_along waits for its moves
  const Sphere ball = sim.region_moves()->ball;
  // Edge radially out (+x), 12 mm deep, 3 cm along z; the ball (R 2.5 cm) is 5 cm away.
  const double z0 = 0.07, z1 = 0.10;
  std::vector<BladePose> path;
  test::append_line(path, Vec3(0.048, 0.003, z0), Vec3(0.048, 0.003, z0), 1,
                    Eigen::Quaterniond::Identity());
  test::append_line(path, Vec3(0.048, 0.003, z0), Vec3(0.048, 0.003, z1), 30,
                    Eigen::Quaterniond::Identity());
  ASSERT_GT((path.front().position - ball.center).norm(), ball.radius + 0.02);
  const CutOutcome cut = sim.cut_along(path);
  // Opened cut faces per centimetre of the path (rest z), and how far they lie from the blade
  // plane y = 0.003 in the deformed tissue, where the blade was: the tissue sags ~1 cm under
  // gravity there, so the cut lies ~1 cm above the plane in rest coordinates.
  std::vector<int> per_cm(3, 0);
  double off_plane = 0;
  const TetMesh& m = sim.mesh();
  const DeformedSurface deformed = sim.surface();
  for (const BoundaryTriangle& tri : extract_boundary_surface(m).triangles) {
    if (!tri.cut) continue;
    Vec3 c = Vec3::Zero(), x = Vec3::Zero();
    for (int v : tri.nodes) c += m.nodes[v] / 3, x += deformed.positions[v] / 3;
    const int bin = static_cast<int>(std::floor((c.z() - z0) / 0.01));
    if (bin >= 0 && bin < 3) ++per_cm[bin];
    off_plane = std::max(off_plane, std::abs(x.y() - 0.003));
  }
  const double error = test::relative_error_vs_full_model(sim);
  std::printf(
      "~cut path starting %.1f cm from the ball centre: %s; %d tets split, %d cut faces, %d "
      "region moves (%d failed); opened faces per cm %d %d %d, at most %.2f mm off the blade "
      "plane (deformed); vs full model %.2e\n",
      100 * (path.front().position - ball.center).norm(), cut.message.c_str(), cut.tets_split,
      cut.cut_faces, sim.region_moves()->moves, sim.region_moves()->failed, per_cm[0], per_cm[1],
      per_cm[2], 1e3 * off_plane, error);
  EXPECT_TRUE(cut.success) << cut.message;
  EXPECT_GT(cut.cut_faces, 0);
  EXPECT_GE(sim.region_moves()->moves, 1);
  EXPECT_EQ(sim.region_moves()->failed, 0);
  for (int k = 0; k < 3; ++k)
    EXPECT_GE(per_cm[k], 2) << "no opened faces in centimetre " << k << " of the path";
  EXPECT_LT(off_plane, 0.003) << "the cut is not where the blade went through the tissue";
  EXPECT_LT(error, 1e-9);
}

// A bar fixed at one end, the ball around its middle: a cut across the whole bar inside the ball
// frees the far end, whose outer half is condensed. That end touches only this partition's
// interface, which holds nothing once the region moves (and here the condensed half floats with
// it): it must be held at the cut that frees it, and the solve must stay exact.
TEST(FollowRegion, BarCutInTwoHoldsTheEndThatOnlyTheInterfaceTouched) {
  test::TempDir dir;
  const Scene scene = load_scene(test::write_file(
      dir.file("bar.yaml"),
      "mesh: {generator: {type: box, size: [0.1, 0.02, 0.02], cells: [20, 4, 4]}}\n"
      "fixed: [{box: {min: [-1, -1, -1], max: [0.001, 1, 1]}}]\n"
      "operation_region: {follow: {radius: 0.02}}\n"
      "material: {young_modulus: 1.0e6}\n"
      "gravity: [0, -9.81, 0]\n"
      "scalpel: {blade_length: 0.04}\n"
      "trajectory: [{t: 0, position: [0.0525, -0.01, 0.01]}]\n"
      "solver: {tolerance: 1.0e-12}\n"));
  SimulationOptions offline;
  offline.wait_for_region_moves = true;
  offline.wait_for_factor_ahead = true;
  Simulation sim(scene, offline);
  // Edge along +y across the bar's height, blade normal along x: the blade plane x = 0.0525
  // (between node planes) sweeps along z through the whole width.
  Eigen::Matrix3d r;
  r.col(0) = Vec3::UnitY();
  r.col(1) = Vec3::UnitX();
  r.col(2) = -Vec3::UnitZ();
  std::vector<BladePose> path;
  test::append_line(path, Vec3(0.0525, -0.01, -0.01), Vec3(0.0525, -0.01, 0.03), 8,
                    Eigen::Quaterniond(r));
  const CutOutcome cut = sim.cut_along(path);
  ASSERT_TRUE(cut.success) << cut.message;
  int condensed_far_end = 0;
  for (int t : sim.model().partition().condensed_tets) {
    Vec3 c = Vec3::Zero();
    for (int v : sim.mesh().tets[static_cast<size_t>(t)]) c += 0.25 * sim.mesh().nodes[v];
    condensed_far_end += c.x() > 0.0525;
  }
  const StepStats s = sim.step(std::nullopt);
  const double error = test::relative_error_vs_full_model(sim);
  const int moves = sim.region_moves()->moves;
  // What a move's worker builds: a re-partition around the fixed end holding the free end's
  // nodes factors the hybrid matrix without them (SPD, no shift); without them it cannot.
  const std::vector<MeshPiece> free = free_pieces(sim.mesh(), sim.model().fixed_nodes());
  ASSERT_EQ(free.size(), 1u);
  const Sphere fixed_end{Vec3(0.0125, 0.01, 0.01), 0.02};
  const auto labels = follow_region_labels(sim.mesh(), fixed_end, free[0].nodes);
  const HybridModel holding(sim.model(), labels, free[0].nodes);
  const HybridModel not_holding(sim.model(), labels);
  EXPECT_EQ(holding.solver().preconditioner(), "cholesky");
  EXPECT_NE(not_holding.solver().preconditioner(), "cholesky");
  // Then the blade comes down on the bar near its fixed end: the region moves there, and the
  // new model must hold the free end (all of it in part 1 now) from its first factorization.
  std::vector<BladePose> press;
  test::append_line(press, Vec3(0.0125, 0.03, 0.01), Vec3(0.0125, 0.0195, 0.01), 10,
                    Eigen::Quaterniond(r));
  for (const BladePose& p : press) EXPECT_TRUE(sim.step(p).converged);
  const StepStats after = sim.step(std::nullopt);
  const double error_after = test::relative_error_vs_full_model(sim);
  int held = 0;
  for (std::uint8_t h : sim.model().held_nodes()) held += h;
  std::printf(
      "bar cut in two: %d tets of the free end condensed, %d pieces held, %d moves, vs full "
      "model %.2e; after the press %d moves, %d nodes held, vs full model %.2e\n",
      condensed_far_end, sim.counts().free_pieces_held, moves, error, sim.region_moves()->moves,
      held, error_after);
  EXPECT_GT(condensed_far_end, 0) << "the free end must reach into the condensed part";
  EXPECT_EQ(sim.counts().free_pieces_held, 1);
  EXPECT_TRUE(s.converged) << s.solver_message;
  EXPECT_LT(error, 1e-9);
  EXPECT_GT(sim.region_moves()->moves, moves);
  EXPECT_EQ(sim.region_moves()->failed, 0);
  EXPECT_TRUE(after.converged) << after.solver_message;
  EXPECT_TRUE(sim.full_displacement().allFinite());
  EXPECT_LT(error_after, 1e-9);
}

struct StrokeResult {
  int steps = 0, moves = 0, steps_waiting = 0;
  double opened = 0, swept = 0, error_vs_full = 0, max_gap = 0;
  std::string hash;  // the final mesh
  Vector u;          // the final displacement, every node
};

// The mesh as the tissue lies now: rest nodes plus the displacement (a sagging organ's shape).
TetMesh deformed_mesh(Simulation& sim) {
  TetMesh m = sim.mesh();
  const Vector u = sim.full_displacement();
  for (int i = 0; i < m.num_nodes(); ++i) m.nodes[static_cast<size_t>(i)] += u.segment<3>(3 * i);
  return m;
}

// Plays `poses` step by step; docs/SCENE.md "Cut invariants" and convergence after every step; at
// the end the cut's opened area (one lip) against the area the edge swept inside the tissue, and
// the largest gap along the stroke (`axis`) between opened cut faces near the blade plane.
// The swept area is measured in the tissue as it lies before the stroke (a liver sagging
// under gravity: where the blade really passes through it), the opened area on the rest mesh;
// they differ by the tissue's strain (a few per cent).
StrokeResult play_stroke(Simulation& sim, const std::vector<BladePose>& poses, const Vec3& axis,
                         double from, double to) {
  StrokeResult r;
  const TetMesh before = deformed_mesh(sim);
  for (const BladePose& p : poses) {
    const StepStats s = sim.step(p);
    ++r.steps;
    r.steps_waiting += s.region_moving;
    if (std::getenv("FOLLOW_TRACE"))
      std::printf(
          "step %3d z %.4f cut %d split %3d iface %d moving %d moved %d centre %.4f %.4f %.4f\n",
          static_cast<int>(s.step), p.position.z(), s.cutting, s.tets_split, s.reached_interface,
          s.region_moving, s.region_moved,
          sim.region_moves() ? sim.region_moves()->ball.center.x() : 0.0,
          sim.region_moves() ? sim.region_moves()->ball.center.y() : 0.0,
          sim.region_moves() ? sim.region_moves()->ball.center.z() : 0.0);
    EXPECT_TRUE(s.converged) << "step " << s.step << ": " << s.solver_message;
    const auto violated = test::spec6_violations(sim);
    EXPECT_TRUE(violated.empty()) << "step " << s.step << ": " << violated.front();
    if (!violated.empty()) break;
  }
  sim.settle_region_move();
  sim.step(std::nullopt);  // a last solve with the blade gone
  r.moves = sim.region_moves() ? sim.region_moves()->moves : 0;
  r.opened = 0.5 * test::open_cut_area(sim.mesh());
  r.swept = test::swept_area_inside(before, poses, sim.scene().scalpel.blade_length);
  r.error_vs_full = test::relative_error_vs_full_model(sim);
  r.hash = sim.mesh_hash();
  r.u = sim.full_displacement();
  // Gaps: positions along the axis of opened cut faces.
  std::vector<double> along;
  const TetMesh& m = sim.mesh();
  for (const BoundaryTriangle& tri : extract_boundary_surface(m).triangles)
    if (tri.cut) {
      const Vec3 c = (m.nodes[tri.nodes[0]] + m.nodes[tri.nodes[1]] + m.nodes[tri.nodes[2]]) / 3;
      along.push_back(c.dot(axis));
    }
  std::sort(along.begin(), along.end());
  double last = from;
  for (double x : along)
    if (x >= from && x <= to) {
      r.max_gap = std::max(r.max_gap, x - last);
      last = x;
    }
  r.max_gap = std::max(r.max_gap, to - last);
  if (std::getenv("FOLLOW_TRACE")) {
    std::printf("closed cut faces %d; opened faces along:", test::closed_cut_faces(m));
    for (double x : along) std::printf(" %.1f", x * 1e3);
    std::printf("\n");
  }
  return r;
}

void report(const char* name, const Simulation& sim, const StrokeResult& r) {
  const RegionMoveStats m = sim.region_moves() ? *sim.region_moves() : RegionMoveStats{};
  std::printf(
      "%s: %d tets, %d steps, %d region moves (%d failed; worker last %.1f ms, max "
      "%.1f ms), %d steps with a move under way; %d pieces held; opened %.2f cm^2 of %.2f cm^2 "
      "swept (%.1f %%); largest gap %.2f mm; vs full model %.2e\n",
      name, sim.counts().tets, r.steps, r.moves, m.failed, m.last_ms, m.max_ms, r.steps_waiting,
      sim.counts().free_pieces_held, r.opened * 1e4, r.swept * 1e4, 100 * r.opened / r.swept,
      r.max_gap * 1e3, r.error_vs_full);
}

// The thigh (whole tube refined, 14 cm long), a 3 cm ball: a 10 cm incision along it,
// against the same stroke with `operation_region: all` (nothing condensed, nothing moves):
// the moves must cost no cut area and leave no gap that the cutter alone does not leave.
// Why 3 cm and not kThighFollowYaml's 2.5: the blade's edge is 12 mm deep, and a 2.5 cm ball
// less its uncut element layer leaves the heel's path at the edge of what can be cut, so the
// conformed borders there stay unconformed (86 % opened offline, a 10.6 mm gap; checked at
// the end); at 3 cm the moves cost nothing against `all`, and the region moves less often.
TEST(FollowRegion, TenCentimetreStrokeAcrossTheThigh) {
  test::TempDir dir;
  const std::string path = test::write_file(dir.file("s.yaml"), kThighFollowYaml);
  Scene scene = load_scene(path);
  scene.operation_region.sphere.radius = 0.03;
  const Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  // edge radially out (+x)
  std::vector<BladePose> poses;
  const double x_in = 0.06 - 0.012;
  test::append_line(poses, Vec3(0.065, 0.003, 0.02), Vec3(0.065, 0.003, 0.02), 1, q);
  test::append_line(poses, Vec3(0.065, 0.003, 0.02), Vec3(x_in, 0.003, 0.02), 17, q);  // press
  test::append_line(poses, Vec3(x_in, 0.003, 0.02), Vec3(x_in, 0.003, 0.12), 200, q);  // draw
  test::append_line(poses, Vec3(x_in, 0.003, 0.12), Vec3(0.07, 0.003, 0.12), 20, q);   // lift
  SimulationOptions offline;
  offline.wait_for_region_moves = true;
  offline.wait_for_factor_ahead = true;
  Simulation follow(scene, offline);
  const StrokeResult r = play_stroke(follow, poses, Vec3::UnitZ(), 0.03, 0.11);
  report("thigh 10 cm stroke, follow", follow, r);
  Scene all = scene;
  all.operation_region.kind = OperationRegion::Kind::kAll;
  Simulation reference(all);
  const StrokeResult b = play_stroke(reference, poses, Vec3::UnitZ(), 0.03, 0.11);
  report("thigh 10 cm stroke, all (no moves)", reference, b);
  // Against the area swept inside the tissue as it hangs: issue 16 asks 90 %. With `all` the
  // conformed borders (docs/DESIGN.md section 8, "Borders") open 109 % of this stroke, with
  // moves awaited 110 % (stop 27); with faces reaching 3/4 of the front margin past the blade
  // (stop 28) 97.5 % against `all`'s 110 %: the moves end and restart strokes, and each end
  // now opens less past the blade. Since a tilted stroke's start and faces past the blade
  // are found again as it moves on (stop 47) `all` opens 128 % (follow 104 %, largest gaps 4.1
  // and 6.6 mm, from 9.7 and 7.6): what `all` opens past the swept area is not the mark, so
  // follow is held to 85 % of it up to that area.
  EXPECT_GE(r.opened, 0.85 * std::min(b.opened, b.swept));
  EXPECT_GE(r.opened, 0.9 * r.swept);
  EXPECT_LE(r.max_gap, b.max_gap + 0.003);  // no gap at the moves beyond the cutter's own
  EXPECT_LT(r.error_vs_full, 1e-9);
  EXPECT_LT(b.error_vs_full, 1e-9);
  // Not the same mesh as `all` any more: a cut is carried to rest coordinates through the
  // deformed operation-part tet containing each blade point (cutting/rest_mapping), and the
  // follow ball's part 1 is not `all`'s, so the inserted sweep can differ by a node. The
  // checks above (area within 10 %, no extra gap, exact vs the full model) still hold.
  std::printf("thigh, follow (offline) vs all: final meshes %s\n",
              r.hash == b.hash ? "identical" : "differ (rest mapping through part 1)");
  // Online: the loop never waits; the cut waits at the interface while a move runs and
  // catches up at the swap. Not deterministic in when it moves, so no mesh comparison.
  Simulation online(scene);
  const StrokeResult o = play_stroke(online, poses, Vec3::UnitZ(), 0.03, 0.11);
  report("thigh 10 cm stroke, follow online", online, o);
  EXPECT_GE(o.moves, 3);
  // Unpaced (steps back to back: the blade crosses the 10 cm in about a second while a move
  // takes ~0.1 s), so how much waits for each move depends on the machine's load: 83-102 %
  // of the swept area over six runs (the paced run below: 109-114 %).
  EXPECT_GE(o.opened, 0.75 * r.swept);
  EXPECT_LT(o.error_vs_full, 1e-9);
  // Online with no cutting budget: each step cuts one run of waiting sweeps at most, and the
  // step that swaps a moved region in cuts none (they are cut through the new model's own
  // solution from the next step on, docs/DESIGN.md section 10a "Swap"); the backlog is still
  // cut, and the end is exact.
  SimulationOptions unhurried;
  unhurried.waiting_cut_budget_ms = 0;
  Simulation paced(scene, unhurried);
  int swaps = 0, swaps_cutting = 0, cutting_steps = 0, waited = 0;
  for (const BladePose& p : poses) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // a 100 Hz loop: moves finish
    const StepStats st = paced.step(p);
    ASSERT_TRUE(st.converged) << "step " << st.step << ": " << st.solver_message;
    if (std::getenv("FOLLOW_TRACE"))
      std::printf("paced step %d moving %d moved %d cutting %d iface %d contact %d force %.3f\n",
                  static_cast<int>(st.step), st.region_moving, st.region_moved, st.cutting,
                  st.reached_interface, st.in_contact, st.contact_force.norm());
    swaps += st.region_moved;
    swaps_cutting += st.region_moved && st.cutting;
    cutting_steps += st.cutting;
    if (st.region_moved) {
      // The collision tree the worker built is the new partition's operation surface, in its
      // order (part-2 triangles first), as one extracted afresh on the loop would be.
      OperationSurface fresh;
      fresh.init(paced.mesh(), paced.model().partition().operation_tet);
      const auto expected = fresh.current(paced.mesh()).triangles;
      const auto taken = paced.surface_snapshot().triangles;
      ASSERT_EQ(taken.size(), expected.size()) << "step " << st.step;
      for (size_t i = 0; i < taken.size(); ++i)
        ASSERT_EQ(taken[i].nodes, expected[i].nodes) << "step " << st.step << ", triangle " << i;
    }
    // The lag the step reports: the waiting sweeps' travel, each at most this stroke's
    // largest step (1.1 mm: the lift), nothing when none waits.
    EXPECT_GE(st.sweeps_waiting, 0);
    EXPECT_LE(st.cut_lag, 1.1e-3 * st.sweeps_waiting + 1e-12) << "step " << st.step;
    EXPECT_EQ(st.cut_lag > 0, st.sweeps_waiting > 0) << "step " << st.step;
    waited = std::max(waited, st.sweeps_waiting);
  }
  EXPECT_GT(waited, 0);  // the sweeps waited for the moves (and their catch-up)

  paced.settle_region_move();
  const StepStats after = paced.step(std::nullopt);
  EXPECT_EQ(after.sweeps_waiting, 0);  // settled: every waiting sweep is cut
  EXPECT_EQ(after.cut_lag, 0);
  const double paced_opened = 0.5 * test::open_cut_area(paced.mesh());
  const double paced_error = test::relative_error_vs_full_model(paced);
  std::printf(
      "thigh 10 cm stroke, follow online, no cutting budget: %d swaps (%d cutting), %d cutting "
      "steps, opened %.2f cm^2, vs full model %.2e\n",
      swaps, swaps_cutting, cutting_steps, paced_opened * 1e4, paced_error);
  EXPECT_GE(swaps, 3);
  EXPECT_EQ(swaps_cutting, 0);
  // 109-114 % of the swept area on an idle machine; 80 % with two other test processes on its
  // two cores (moves up to 0.3 s, 9 swaps instead of 11-12): the cut waits for the moves, so
  // how much of it the stroke's end leaves uncut depends on the machine.
  EXPECT_GE(paced_opened, 0.75 * r.swept);
  EXPECT_TRUE(test::spec6_violations(paced).empty());
  EXPECT_LT(paced_error, 1e-9);
  // The 2.5 cm ball (kThighFollowYaml, config/scenes/thigh_follow.yaml), moves awaited: the
  // heel's path runs along the uncut layer, where a border is not conformed; what the next
  // move frees is cut by later sweeps, not by the one that passed. 86 % opened and a 10.6 mm
  // gap (85 % and 4.1 mm before the conformed borders): under one operation tet.
  const Scene small = load_scene(path);
  Simulation tight(small, offline);
  const StrokeResult t = play_stroke(tight, poses, Vec3::UnitZ(), 0.03, 0.11);
  report("thigh 10 cm stroke, follow, 2.5 cm ball", tight, t);
  EXPECT_GE(t.opened, 0.8 * t.swept);
  EXPECT_LE(t.max_gap, 0.011);
  EXPECT_LT(t.error_vs_full, 1e-9);
}

// The same stroke with every pose held for three steps (a lockstep bag replay through
// tissue_node does that): a blade held still sweeps nothing, so it must cost no region moves.
// Before, a held step moved the ball back around the blade (no motion to look ahead by) and
// the next sweep pushed it ahead again: 429 moves instead of 49, and online a backlog of
// waiting sweeps the loop never caught up with.
TEST(FollowRegion, BladeHeldStillMidStrokeCostsNoMoves) {
  // config/scenes/thigh_follow.yaml: the thigh of TenCentimetreStrokeAcrossTheThigh.
  Scene scene =
      load_scene(std::string(TISSUE_TEST_DATA_DIR) + "/../../config/scenes/thigh_follow.yaml");
  scene.solver.tolerance = 1e-12;
  std::vector<BladePose> poses;
  const double x_in = 0.048;
  const Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  test::append_line(poses, Vec3(0.065, 0.003, 0.02), Vec3(0.065, 0.003, 0.02), 1, q);
  test::append_line(poses, Vec3(0.065, 0.003, 0.02), Vec3(x_in, 0.003, 0.02), 17, q);  // press
  test::append_line(poses, Vec3(x_in, 0.003, 0.02), Vec3(x_in, 0.003, 0.12), 200, q);  // draw
  test::append_line(poses, Vec3(x_in, 0.003, 0.12), Vec3(0.07, 0.003, 0.12), 20, q);   // lift
  std::vector<BladePose> held;
  for (const BladePose& p : poses) held.insert(held.end(), 3, p);
  SimulationOptions offline;
  offline.wait_for_region_moves = true;
  offline.wait_for_factor_ahead = true;
  Simulation once(scene, offline), thrice(scene, offline);
  const StrokeResult a = play_stroke(once, poses, Vec3::UnitZ(), 0.03, 0.11);
  report("thigh 10 cm stroke, one step per pose", once, a);
  const StrokeResult b = play_stroke(thrice, held, Vec3::UnitZ(), 0.03, 0.11);
  report("thigh 10 cm stroke, each pose held for three steps", thrice, b);
  EXPECT_GE(a.moves, 3);
  EXPECT_LE(b.moves, a.moves + a.moves / 4);
  EXPECT_GE(b.opened, 0.9 * a.opened);
  EXPECT_LE(b.max_gap, a.max_gap + 0.003);
  EXPECT_LT(b.error_vs_full, 1e-9);
}

// The TetGen liver of the follow tests: sofa_liver2.obj scaled to ~11 x 6 x 7 cm, TetGen `pQ`
// (5.7k tets), its underside fixed, under gravity, a 3 cm follow ball.
Scene follow_liver_scene(const test::TempDir& dir, double blade_length, const Vec3& start) {
  std::ostringstream yaml;
  yaml << "mesh: {file: " << TISSUE_SHARED_MESH_DIR
       << "/sofa_liver2.obj, scale: 0.05, tetgen: {switches: \"pQ\"}}\n"
          "fixed: [{box: {min: [-0.08, -0.06, 0.71], max: [0.04, -0.047, 0.79]}}]\n"
          "operation_region: {follow: {radius: 0.03}}\n"
          "gravity: [0, -9.81, 0]\n"
          "scalpel: {blade_length: "
       << blade_length << ", cut_pressure: 0.01}\n"
       << "trajectory: [{t: 0, position: [" << start.x() << ", " << start.y() << ", " << start.z()
       << "]}]\n"
       << "solver: {tolerance: 1.0e-11}\n";
  return load_scene(test::write_file(dir.file("s.yaml"), yaml.str()));
}

// The highest point of the liver `mesh` (rest or sagged) above (x, z): its top surface along a
// stroke line.
double liver_top(const TetMesh& mesh, const TetGrid& grid, double x, double z) {
  for (double y = 0.01; y > -0.05; y -= 0.0002)
    if (tet_containing(mesh, grid, Vec3(x, y, z)) >= 0) return y;
  return std::numeric_limits<double>::quiet_NaN();
}

// A blade orientation from its edge (tip to heel), blade normal and travel directions.
Eigen::Quaterniond blade_frame(const Vec3& edge, const Vec3& normal, const Vec3& travel) {
  Eigen::Matrix3d r;
  r.col(0) = edge;
  r.col(1) = normal;
  r.col(2) = travel;
  return Eigen::Quaterniond(r);
}

// A TetGen liver (sofa_liver2.obj scaled to ~11 x 6 x 7 cm, TetGen `pQ`: 5.7k tets), a 3 cm
// ball: a 10 cm stroke along x across its top (9.1 cm of it on the liver), 6 mm below the
// surface it has sagged to under gravity, edge up, against `operation_region: all`. Cut pieces come
// free on the way and are held across the moves. Why 3 cm and not 2 cm: this mesh's edges are ~7
// mm, and a 2 cm ball (under 3 elements) cannot hold the blade's edge one element layer plus the
// look-ahead clear of its interface, so sweeps wait at it and the cut opens 83 % of `all`'s
// (5.6 vs 6.7 cm^2, 108 moves); at 3 cm it opens as much as `all`. Why a solver
// tolerance of 1e-11: the `all` reference on the cut liver stalls at a relative residual of
// ~1.3e-12.
TEST(FollowRegion, TenCentimetreStrokeAcrossATetGenLiver) {
  test::TempDir dir;
  const Scene scene = follow_liver_scene(dir, 0.02, Vec3(-0.065, 0.01, 0.768));
  // The blade follows the top of the liver as it sags under gravity (up to ~1 cm here), 6 mm
  // inside it: the rest top would put it in the air where the tissue has sagged away.
  Simulation hanging(scene);
  const TetMesh sagged = deformed_mesh(hanging);
  TetGrid grid;
  grid.build(sagged, {});
  auto top = [&](double x) { return liver_top(sagged, grid, x, 0.768); };
  // Edge along world +y (up), blade normal along world z: the blade plane holds the x motion.
  const Eigen::Quaterniond q = blade_frame(Vec3::UnitY(), Vec3::UnitZ(), Vec3::UnitX());
  const double depth = 0.006, x0 = -0.065, x1 = 0.035;
  ASSERT_FALSE(std::isnan(top(x0)));
  std::vector<BladePose> poses;
  const Vec3 above(x0, top(x0) + 0.005, 0.768), in(x0, top(x0) - depth, 0.768);
  test::append_line(poses, above, above, 1, q);
  test::append_line(poses, above, in, 20, q);  // press down, edge first: presses, then yields
  Vec3 last = in;
  for (int k = 1; k <= 200; ++k) {  // 0.5 mm per step, following the surface
    const double x = x0 + (x1 - x0) * k / 200;
    const double y = top(x);
    if (std::isnan(y)) break;  // off the liver
    const Vec3 next(x, y - depth, 0.768);
    test::append_line(poses, last, next, 1, q);
    last = next;
  }
  const double stroke = last.x() - x0;
  test::append_line(poses, last, last + Vec3(0, 0.03, 0), 20, q);  // lift out along the edge
  SimulationOptions offline;
  offline.wait_for_region_moves = true;
  offline.wait_for_factor_ahead = true;
  Simulation follow(scene, offline);
  const StrokeResult f = play_stroke(follow, poses, Vec3::UnitX(), x0 + 0.01, last.x() - 0.01);
  std::printf("liver stroke %.1f cm\n", stroke * 100);
  report("liver stroke, follow", follow, f);
  Scene all = scene;
  all.operation_region.kind = OperationRegion::Kind::kAll;
  Simulation reference(all);
  const StrokeResult b = play_stroke(reference, poses, Vec3::UnitX(), x0 + 0.01, last.x() - 0.01);
  report("liver stroke, all (no moves)", reference, b);
  EXPECT_GT(stroke, 0.08);
  EXPECT_GE(f.moves, 3);
  EXPECT_GE(f.opened, 0.9 * b.opened);
  EXPECT_GE(f.opened, 0.9 * f.swept);  // issue 16: 90 % of the area swept inside the tissue
  EXPECT_LE(f.max_gap, b.max_gap + 0.003);
  EXPECT_LT(f.error_vs_full, 1e-9);
  EXPECT_LT(b.error_vs_full, 1e-9);
  // The liver's cut may differ from `all` by a node (both 6211 tets, different meshes, at the
  // time of writing): a sweep is carried to rest through part 1, which differs. Reported, not
  // asserted.
  std::printf("liver: final meshes %s\n", f.hash == b.hash ? "identical" : "differ");
}

// The TetGen liver's thin lobe (x > 0.018, y from -0.045 to -0.018, not fixed), a 3 cm ball: a
// vertical blade slices across the lobe along z at x = 0.028 through its whole (sagging)
// thickness, then a second stroke runs 4 cm along the top of the body. The slice cuts pieces
// free mid-stroke while the region moves on around the blade: every model a move builds must
// hold them (their nodes out of its first factorization; a piece is free unless fixed nodes
// hold it, whatever one partition's interface touches), every step must converge, and the end
// must equal the full model. The lobe's tip itself stays attached (the cutter leaves face
// bridges across the slice through the sagging lobe, here and with `operation_region: all`
// alike); the pieces the slice frees are small (one of 16 nodes at the time of writing) but
// free all the same. Which slice frees one depends on the cutter's details: at x = 0.018 it
// freed 1-3-tet pieces until stop 46 limited how far ahead of the blade a face opens
// (CutOptions::front_corner_reach), and none since; at x = 0.025 it freed one until stop 47
// (faces past the blade tested again as it moves on), and of x = 0.018, 0.020, ..., 0.030 only
// 0.028 frees one since (at a 1 deg shape guard, see below).
TEST(FollowRegion, LiverPiecesCutFreeMidStrokeStayHeldAcrossMoves) {
  test::TempDir dir;
  Scene scene = follow_liver_scene(dir, 0.06, Vec3(0.018, -0.07, 0.75));
  // At 1 deg: under the 5 deg default (stop 51) no slice at x = 0.018, 0.019, ..., 0.032 frees
  // a piece (the guard moves or snaps the splits that left the small ones), and this test is
  // about what the region does with one.
  scene.scalpel.shape_guard_deg = 1;
  std::vector<BladePose> lobe, top;
  {  // Edge up (+y) from below the lobe to above it, blade normal along x: the blade plane
     // holds the z motion; 0.5 mm per step from one side of the lobe to the other.
    const Eigen::Quaterniond q = blade_frame(Vec3::UnitY(), Vec3::UnitX(), -Vec3::UnitZ());
    const Vec3 from(0.028, -0.07, 0.75), to(0.028, -0.07, 0.792);
    test::append_line(lobe, from, from, 1, q);
    test::append_line(lobe, from, to, 84, q);
  }
  {  // Then 4 cm along -x on the top of the body, 6 mm deep, edge up (as the 10 cm stroke).
    const Eigen::Quaterniond q = blade_frame(Vec3::UnitY(), Vec3::UnitZ(), Vec3::UnitX());
    TetGrid grid;
    grid.build(scene.mesh, {});
    auto surface = [&](double x) { return liver_top(scene.mesh, grid, x, 0.768); };
    const double depth = 0.006, x0 = 0.0, x1 = -0.04;
    const Vec3 above(x0, surface(x0) + 0.005, 0.768), in(x0, surface(x0) - depth, 0.768);
    test::append_line(top, above, above, 1, q);
    test::append_line(top, above, in, 20, q);
    Vec3 last = in;
    for (int k = 1; k <= 80; ++k) {
      const double x = x0 + (x1 - x0) * k / 80;
      const Vec3 next(x, surface(x) - depth, 0.768);
      ASSERT_TRUE(next.allFinite()) << "off the liver at x " << x;
      test::append_line(top, last, next, 1, q);
      last = next;
    }
    test::append_line(top, last, last + Vec3(0, 0.03, 0), 20, q);
  }
  SimulationOptions offline;
  offline.wait_for_region_moves = true;
  offline.wait_for_factor_ahead = true;
  int logged_pieces = 0, found_at_moves = 0;
  offline.log = [&](LogLevel, const std::string& m) {
    logged_pieces += test::pieces_reported(m);
    found_at_moves += m.find("found free at a region move") != std::string::npos;
  };
  Simulation sim(scene, offline);
  int steps = 0, unconverged = 0, first_held_step = -1, moves_before = 0;
  bool keeps_invariants = true;
  auto play = [&](const std::optional<BladePose>& pose) {
    const StepStats s = sim.step(pose);
    ++steps;
    unconverged += !s.converged;
    EXPECT_TRUE(s.converged) << "step " << s.step << ": " << s.solver_message;
    if (first_held_step < 0 && sim.counts().free_pieces_held > 0) {
      first_held_step = steps;
      moves_before = sim.region_moves()->moves;
    }
    const auto violated = test::spec6_violations(sim);
    if (keeps_invariants && !violated.empty()) {
      keeps_invariants = false;
      ADD_FAILURE() << "step " << s.step << ": " << violated.front();
    }
  };
  for (const BladePose& p : lobe) play(p);
  const int lobe_steps = steps;
  for (int k = 0; k < 3; ++k) play(std::nullopt);
  for (const BladePose& p : top) play(p);
  sim.settle_region_move();
  play(std::nullopt);
  const Vector u = sim.full_displacement();
  const double error = test::relative_error_vs_full_model(sim);
  const RegionMoveStats& m = *sim.region_moves();
  int held_nodes = 0;
  for (std::uint8_t h : sim.model().held_nodes()) held_nodes += h;
  std::printf(
      "liver, pieces cut free: %d steps (%d slicing the lobe), %d pieces held (the first at "
      "step %d, after %d of %d region moves; %d failed), %d nodes held in the last model, %d "
      "unconverged, max |u| %.2f mm, vs full model %.2e\n",
      steps, lobe_steps, sim.counts().free_pieces_held, first_held_step, moves_before, m.moves,
      m.failed, held_nodes, unconverged, 1e3 * u.cwiseAbs().maxCoeff(), error);
  ASSERT_GE(first_held_step, 0) << "the slice must cut a piece free";
  EXPECT_LE(first_held_step, lobe_steps) << "cut free mid-stroke, while slicing the lobe";
  EXPECT_EQ(logged_pieces, sim.counts().free_pieces_held) << "each reported on the log sink";
  // Each held by the cut that frees it, not only by the next move's model: whatever this
  // partition's interface touches does not hold a piece once the region moves.
  EXPECT_EQ(found_at_moves, 0);
  EXPECT_GE(m.moves - moves_before, 3) << "the region must move on with the pieces held";
  EXPECT_EQ(m.failed, 0);
  EXPECT_GT(held_nodes, 0);
  EXPECT_EQ(unconverged, 0);
  EXPECT_TRUE(u.allFinite());
  EXPECT_LT(error, 1e-9);
}

}  // namespace
}  // namespace stc
