// docs/SCENE.md "Cut invariants" at the simulation level: random blade sweeps through the thigh's
// operation part via Simulation::cut_along (cut insertion + re-assembly + free pieces held +
// solve). After every sweep: the geometric invariants, a symmetric hybrid matrix that is positive
// definite on the free DOF (held pieces excluded: they are constrained), a converged finite
// solution.
#include "common/cut_fidelity_scenes.hpp"
#include "common/cut_measures.hpp"
#include "common/free_piece_log.hpp"
#include "cutting/free_pieces.hpp"
#include "soft_tissue_cutting/cutting/invariants.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

namespace stc {
namespace {

// The nodes of free pieces, found again here (anchored by fixed and interface nodes): what
// must be held for the rest of the hybrid system to stay SPD.
std::vector<std::uint8_t> held_nodes(const Simulation& sim) {
  const HybridModel& model = sim.model();
  std::vector<std::uint8_t> anchored = model.fixed_nodes();
  for (int i : model.partition().interface) anchored[static_cast<size_t>(i)] = 1;
  std::vector<std::uint8_t> held(anchored.size(), 0);
  for (const MeshPiece& piece : free_pieces(model.mesh(), anchored))
    for (int n : piece.nodes) held[static_cast<size_t>(n)] = 1;
  return held;
}

// The held DOFs of the hybrid system (the rows free_block leaves out).
std::vector<std::uint8_t> held_dofs(const Simulation& sim) {
  const std::vector<std::uint8_t> held = held_nodes(sim);
  const DofMap& dofs = sim.model().hybrid_dofs();
  std::vector<std::uint8_t> out(static_cast<size_t>(dofs.rows()), 0);
  for (int r = 0; r < dofs.rows(); ++r)
    out[static_cast<size_t>(r)] =
        held[static_cast<size_t>(dofs.global_of[static_cast<size_t>(r)] / 3)];
  return out;
}

SparseMatrix free_block(const Simulation& sim) {
  return test::free_block(sim.model(), held_nodes(sim));
}

// Why a solve did not converge: the preconditioner that was active, the solver's message, the
// element quality, and the same system re-solved from the held values with each
// preconditioner at growing iteration caps (the residual history), plus a direct solve of the
// free block (the residual double precision can reach at all).
std::string solve_diagnosis(const Simulation& sim) {
  const HybridModel& model = sim.model();
  const CgResult& last = model.last_result();
  const MeshQuality q = mesh_quality(sim.mesh());
  std::ostringstream o;
  o << "preconditioner " << model.solver().preconditioner() << ", " << last.iterations
    << " iterations, residual " << last.residual << " (" << last.message << "); "
    << sim.counts().tets << " tets, " << sim.counts().free_pieces_held << " free pieces held, "
    << model.hybrid_dofs().rows() << " DOFs; min dihedral " << q.min_dihedral_deg
    << " deg, max dihedral " << q.max_dihedral_deg << " deg, min volume ratio "
    << q.min_volume_ratio << ", min volume " << q.min_volume << " m^3";
  const SparseMatrix& a = model.hybrid_matrix();
  const Vector& b = model.hybrid_rhs();
  const std::vector<std::uint8_t> held = held_dofs(sim);
  Vector start = Vector::Zero(a.rows());
  const Vector u = model.operation_displacement();
  for (int r = 0; r < a.rows(); ++r)
    if (held[static_cast<size_t>(r)])
      start[r] = u[model.hybrid_dofs().global_of[static_cast<size_t>(r)]];
  for (CgPreconditioner pc : {CgPreconditioner::kCholesky, CgPreconditioner::kJacobi}) {
    auto solver = make_cpu_solver(pc);
    solver->set_matrix(a);
    o << "\n  " << solver->preconditioner() << " from the held values:";
    for (int cap : {1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 10000}) {
      Vector x = start;
      CgSettings settings = model.cg_settings();
      settings.max_iterations = cap;
      const CgResult r = solver->solve(b, x, held, settings);
      o << " " << r.iterations << ":" << r.residual;
      if (r.converged || r.iterations < cap) break;
    }
  }
  try {
    Vector x = start;
    solve_direct(a, b, x, held);
    Vector r = (b - a * x);
    Vector rf = r, rhs = b - a * start.cwiseProduct(Vector::Ones(a.rows()));
    for (int i = 0; i < a.rows(); ++i)
      if (held[static_cast<size_t>(i)]) rf[i] = rhs[i] = 0;
    o << "\n  direct solve of the free block: relative residual " << rf.norm() / rhs.norm();
  } catch (const std::exception& e) {
    o << "\n  direct solve of the free block failed: " << e.what();
  }
  return o.str();
}

// One random stroke: a straight sweep of `length` * U(-1, 1)^3 starting within `spread` of
// `centre` (x biased outward by `bias`), one random blade orientation.
struct RandomStrokes {
  std::mt19937 rng;
  std::uniform_real_distribution<double> unit{-1.0, 1.0};
  explicit RandomStrokes(unsigned seed) : rng(seed) {}
  std::vector<BladePose> next(const Vec3& centre, double spread, double length, double bias) {
    BladePose a, b;
    a.position = centre + spread * Vec3(unit(rng) - bias, unit(rng), unit(rng));
    b.position = a.position + length * Vec3(unit(rng), unit(rng), unit(rng));
    a.orientation = Eigen::Quaterniond(
        Eigen::Vector4d(unit(rng), unit(rng), unit(rng), unit(rng)).normalized());
    b.orientation = a.orientation;
    return {a, b};
  }
};

// Cuts `strokes` random strokes and checks the cut invariants (docs/SCENE.md "Cut invariants"),
// symmetry and the solve after every one, and positive definiteness (a sparse Cholesky of the free
// block) after every `spd_every`-th and the last; returns how many cut.
int run_random_strokes(Simulation& sim, RandomStrokes& random, int strokes, const Vec3& centre,
                       double spread, double length, double bias, int spd_every = 1) {
  int cuts = 0;
  for (int k = 0; k < strokes; ++k) {
    const CutOutcome out = sim.cut_along(random.next(centre, spread, length, bias));
    cuts += out.success;
    InvariantLimits limits;
    limits.initial_volume = sim.counts().volume_initial;
    const auto violated = check_cut_invariants(sim.mesh(), sim.tet_size_classes(), limits);
    EXPECT_TRUE(violated.empty()) << "sweep " << k << ": " << violated.front();
    const SparseMatrix& a_full = sim.model().hybrid_matrix();
    EXPECT_LT((SparseMatrix(a_full.transpose()) - a_full).norm(), 1e-12 * a_full.norm())
        << "sweep " << k;
    if (k % spd_every == 0 || k + 1 == strokes) {
      EXPECT_NO_THROW(SparseCholesky{free_block(sim)}) << "sweep " << k << ": not SPD";
    }
    EXPECT_TRUE(sim.model().last_result().converged)
        << "sweep " << k << ": "
        << (sim.model().last_result().converged ? std::string() : solve_diagnosis(sim));
    EXPECT_TRUE(sim.model().displacement().allFinite()) << "sweep " << k;
    if (::testing::Test::HasFailure()) return cuts;
  }
  return cuts;
}

TEST(SimulationRandomCuts, EverySweepKeepsSpec6AndAnSpdSystem) {
  const Scene scene = make_thigh_scene();
  // Every piece held is reported through the log sink (the core never prints itself).
  int held_messages = 0;
  SimulationOptions options;
  options.log = [&held_messages](LogLevel level, const std::string& message) {
    EXPECT_EQ(level, LogLevel::kInfo);
    held_messages += test::pieces_reported(message);
  };
  Simulation sim(scene, options);
  RandomStrokes random(20261122);
  constexpr int kSweeps = 200;
  const int cuts = run_random_strokes(sim, random, kSweeps, scene.operation_region.sphere.center,
                                      0.02, 0.03, 0.5);
  std::printf("random sweeps: %d of %d cut, %d tets split, %d tets, %d free pieces held\n", cuts,
              kSweeps, sim.counts().tets_split, sim.counts().tets, sim.counts().free_pieces_held);
  EXPECT_GT(cuts, kSweeps / 3);
  EXPECT_EQ(held_messages, sim.counts().free_pieces_held);
}

// How many strokes the liver property tests cut: TISSUE_RANDOM_CUT_STROKES (./tissue test
// --strokes N: nightly sizes, 10,000) or the CI default.
int stroke_count(int ci_default) {
  const char* env = std::getenv("TISSUE_RANDOM_CUT_STROKES");
  return env ? std::atoi(env) : ci_default;
}

// The same on a TetGen liver sagging under gravity (issues 9 and 12): seeded random strokes
// through its operation part (5k tets at the start): 300 in CI (~1.5 min), 1,000 or more
// through TISSUE_RANDOM_CUT_STROKES (1,000 took 7 min here and passed: 517 cut, 22k tets), each
// stroke carried to rest coordinates through the sag. After every stroke: docs/SCENE.md "Cut
// invariants", an SPD system on the free DOF, a finite solution. The smallest dihedral angle and
// the CG iterations of the solve after each stroke are reported after 100 strokes and at the end
// (issue 9 item 4 asks for >= 5 deg, not met - see README - and <= 2x the uncut mesh's
// iterations, met and asserted).
// One random stroke of the sagging TetGen liver tests: 3 cm at most, from within 2 cm of the
// operation region's centre (biased down into the tissue), any blade orientation.
std::vector<BladePose> random_liver_stroke(std::mt19937& rng, const Vec3& centre) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  BladePose a, b;
  a.position = centre + 0.02 * Vec3(unit(rng), unit(rng) - 0.5, unit(rng));
  b.position = a.position + 0.03 * Vec3(unit(rng), unit(rng), unit(rng));
  a.orientation =
      Eigen::Quaterniond(Eigen::Vector4d(unit(rng), unit(rng), unit(rng), unit(rng)).normalized());
  b.orientation = a.orientation;
  return {a, b};
}

// The operation part's shapes (the condensed part is never cut: its thin tets are the input's).
test::TetShapes operation_shape(const Simulation& sim) {
  return test::tet_shapes(sim.mesh(), sim.model().partition().operation_tet);
}
int thin_operation_tets(const Simulation& sim) { return operation_shape(sim).thin; }
double operation_min_dihedral(const Simulation& sim) { return operation_shape(sim).least; }

TEST(SimulationRandomCuts, TetGenLiverStrokesKeepSpec6) {
  const int strokes = stroke_count(300);
  ASSERT_GT(strokes, 0) << "TISSUE_RANDOM_CUT_STROKES must be a positive number";
  const Scene scene = fidelity::sagging_liver();
  Simulation sim(scene);
  const double dihedral_before = mesh_quality(sim.mesh()).min_dihedral_deg;
  const int cold_iterations = sim.last_stats().cg_iterations;
  std::mt19937 rng(20261123);
  const Vec3 centre = scene.operation_region.sphere.center;
  int cuts = 0;
  std::vector<int> iterations;
  int not_converged = 0;
  double worst_residual = 0;
  int thin_at_100 = -1;
  double dihedral_at_100 = 0;
  const auto report = [&](int done) {
    std::vector<int> sorted = iterations;
    std::sort(sorted.begin(), sorted.end());
    int thin = 0;
    for (const Tet& e : sim.mesh().tets) {
      const auto angles = dihedral_angles_deg(sim.mesh().nodes[e[0]], sim.mesh().nodes[e[1]],
                                              sim.mesh().nodes[e[2]], sim.mesh().nodes[e[3]]);
      thin += *std::min_element(angles.begin(), angles.end()) < 5.0;
    }
    std::printf(
        "TetGen liver, %d random strokes: %d cut, %d tets, %d free pieces held; min dihedral "
        "%.2f -> %.2f deg, %d tets under 5 deg, %d wedges under 5 deg; CG iterations after a "
        "stroke: median %d, max %d (uncut cold solve %d); %d solves short of 1e-10 (worst "
        "residual %.1e)\n",
        done, cuts, sim.counts().tets, sim.counts().free_pieces_held, dihedral_before,
        mesh_quality(sim.mesh()).min_dihedral_deg, thin, test::sharp_wedges(sim.mesh()),
        sorted[sorted.size() / 2], sorted.back(), cold_iterations, not_converged, worst_residual);
    std::fflush(stdout);
    if (done == 100) {
      thin_at_100 = thin;
      dihedral_at_100 = mesh_quality(sim.mesh()).min_dihedral_deg;
    }
  };
  for (int k = 0; k < strokes; ++k) {
    const CutOutcome out = sim.cut_along(random_liver_stroke(rng, centre));
    cuts += out.success;
    iterations.push_back(sim.model().last_result().iterations);
    InvariantLimits limits;
    limits.initial_volume = sim.counts().volume_initial;
    const auto violated = check_cut_invariants(sim.mesh(), sim.tet_size_classes(), limits);
    ASSERT_TRUE(violated.empty()) << "stroke " << k << ": " << violated.front();
    EXPECT_NO_THROW(SparseCholesky{free_block(sim)}) << "stroke " << k << ": not SPD";
    // CG to the scene's 1e-10 within 4000 iterations does not always succeed on the cut
    // liver (a known failure, issue 9 item 4 - see README): counted and reported.
    not_converged += !sim.model().last_result().converged;
    worst_residual = std::max(worst_residual, sim.model().last_result().residual);
    ASSERT_TRUE(sim.model().displacement().allFinite()) << "stroke " << k;
    if (k + 1 == 100 || (k + 1) % 1000 == 0 || k + 1 == strokes) report(k + 1);
  }
  EXPECT_GT(cuts, strokes * 3 / 10);
  // Issue 9 item 4: every solve after a stroke converges, in at most twice the uncut mesh's
  // iterations (measured: 1, as uncut, over 300 strokes; the factor of the cut matrix solves it
  // directly).
  EXPECT_EQ(not_converged, 0);
  EXPECT_LE(*std::max_element(iterations.begin(), iterations.end()),
            2 * std::max(cold_iterations, 1));
  // Shapes (not met: >= 5 deg asked; the input itself starts at 1.9 deg): regression guards
  // with margin over what stop 39 measures after 100 strokes with the flips (171 tets under 5
  // deg, min 0.55 deg; stop 38's smoothing alone 241 / 0.42, stop 37's 261 / 0.55; stop 42's
  // vertex insertion, off by default, 109 / 0.72: TetGenLiverInsertionLeavesFewerThinTets).
  if (strokes >= 100) {
    EXPECT_LE(thin_at_100, 210) << "tets under 5 deg after 100 strokes";
    EXPECT_GT(dihedral_at_100, 0.3) << "min dihedral after 100 strokes";
  }
  // The upkeep is counted where the run reports (stats JSON, ModelCounts): each stroke that
  // follows a cut one smooths and flips that one's tets.
  const ModelCounts counts = sim.counts();
  std::printf("shape upkeep over %d strokes: %d nodes smoothed, %d flips\n", strokes,
              counts.nodes_smoothed, counts.flips);
  EXPECT_GT(counts.nodes_smoothed, 0);
  EXPECT_GT(counts.flips, 0);
}

// What the vertex insertion adds over smoothing and flips (docs/DESIGN.md section 8, "Insert";
// issue 9 item 4): the sagging TetGen liver, 100 random strokes, four seeds, with and without
// it. Measured (stop 42), tets of the operation part under 5 deg: seeds 1-4 without 152 / 136 /
// 124 / 171, with 136 / 70 / 104 / 109 (-29 % in all; seeds 5, 6 and 20261123: 157 -> 106,
// 204 -> 126, 139 -> 77); the smallest angle scatters with the cut sequence either way
// (0.31-1.19 deg with, 0.55-1.02 without). Stop 44, with the default 1 deg shape guard (which
// alone takes the four seeds' 583 to 492): 136 / 94 / 121 / 141 without, 125 / 96 / 93 / 105
// with (-15 %). Asserted: at least 10 % fewer over the four seeds.
TEST(SimulationRandomCuts, TetGenLiverInsertionLeavesFewerThinTets) {
  const Scene scene = fidelity::sagging_liver();
  const Vec3 centre = scene.operation_region.sphere.center;
  std::array<int, 2> thin = {0, 0};
  for (unsigned seed : {1u, 2u, 3u, 4u})
    for (int insert = 0; insert < 2; ++insert) {
      SimulationOptions options;
      options.cut.insert_nodes = insert == 1;
      Simulation sim(scene, options);
      std::mt19937 rng(seed);
      for (int k = 0; k < 100; ++k) sim.cut_along(random_liver_stroke(rng, centre));
      const int here = thin_operation_tets(sim);
      thin[static_cast<size_t>(insert)] += here;
      std::printf(
          "seed %u, insertion %s: %d tets, %d of the operation part under 5 deg, min %.2f deg\n",
          seed, insert ? "on" : "off", sim.counts().tets, here,
          mesh_quality(sim.mesh()).min_dihedral_deg);
      InvariantLimits limits;
      limits.initial_volume = sim.counts().volume_initial;
      const auto violated = check_cut_invariants(sim.mesh(), sim.tet_size_classes(), limits);
      EXPECT_TRUE(violated.empty()) << "seed " << seed << ": " << violated.front();
      EXPECT_TRUE(sim.model().displacement().allFinite());
    }
  std::printf(
      "TetGen liver, 4 x 100 strokes: operation tets under 5 deg %d without insertion, %d with\n",
      thin[0], thin[1]);
  EXPECT_LE(thin[1], 0.9 * thin[0]);
}

// Issue 9 item 4 with the shape guard at its default, 5 deg since stop 51 (scene key
// scalpel.shape_guard_deg, docs/DESIGN.md section 8 "Shape guard"): after every one of 100 random
// strokes on the sagging TetGen liver the operation part's smallest dihedral angle stays at least
// min(5 deg, what it was uncut) - the cutter never makes a tet thinner than 5 deg or than the one
// it splits - with the cut invariants and every solve converged in at most twice the uncut mesh's
// CG iterations. The same strokes without it leave 136-152 tets under 5 deg, 0.55-0.68 deg
// (measured, seeds 20261123, 1, 2; asserted here for seed 1: the guard is what keeps the angle),
// and at 1 deg (the default until stop 51) the angle stays >= 1 deg. Wedges (test::sharp_wedges:
// walls meeting under 5 deg, which no repair lifts): none at 1 or 5 deg since flaps are kept joined
// (stop 50, CutOptions::wedge_min_deg), 6 at 1 deg without that (seed 1), 1 with no guard.
TEST(SimulationRandomCuts, ShapeGuardKeepsTheOperationPartAboveFiveDegrees) {
  const Scene scene = fidelity::sagging_liver();
  const Vec3 centre = scene.operation_region.sphere.center;
  for (unsigned seed : {1u, 2u}) {
    // Seed 2 with the scene's default (which decides: the cutter's own option is overridden by
    // it, docs/SCENE.md), seed 1 set live on an unguarded simulation (dynamic_reconfigure's path).
    SimulationOptions options;
    options.cut.split_min_dihedral_deg = 0;
    Scene guarded = scene;
    if (seed == 1) guarded.scalpel.shape_guard_deg = 0;
    Simulation sim(guarded, options);
    if (seed == 2) {
      EXPECT_EQ(sim.scene().scalpel.shape_guard_deg, 5.0);  // the default
    }
    if (seed == 1) {
      sim.set_shape_guard_deg(5);
      EXPECT_EQ(sim.scene().scalpel.shape_guard_deg, 5.0);
    }
    const double floor = std::min(5.0, operation_min_dihedral(sim)) - 1e-6;
    const int cold_iterations = std::max(sim.last_stats().cg_iterations, 1);
    std::mt19937 rng(seed);
    int cuts = 0;
    for (int k = 0; k < 100; ++k) {
      cuts += sim.cut_along(random_liver_stroke(rng, centre)).success;
      const double least = operation_min_dihedral(sim);
      ASSERT_GE(least, floor) << "seed " << seed << ", stroke " << k;
      InvariantLimits limits;
      limits.initial_volume = sim.counts().volume_initial;
      const auto violated = check_cut_invariants(sim.mesh(), sim.tet_size_classes(), limits);
      ASSERT_TRUE(violated.empty())
          << "seed " << seed << ", stroke " << k << ": " << violated.front();
      ASSERT_TRUE(sim.model().last_result().converged) << "seed " << seed << ", stroke " << k;
      ASSERT_LE(sim.model().last_result().iterations, 2 * cold_iterations)
          << "seed " << seed << ", stroke " << k;
    }
    const int wedges = test::sharp_wedges(sim.mesh());
    std::printf(
        "shape guard, seed %u: %d of 100 strokes cut, %d tets, operation part min dihedral %.2f "
        "deg (floor %.2f), %d of its tets under 5 deg, %d wedges under 5 deg\n",
        seed, cuts, sim.counts().tets, operation_min_dihedral(sim), floor, thin_operation_tets(sim),
        wedges);
    EXPECT_GT(cuts, 30) << "seed " << seed;
    // Where a split would make a wedge of tissue under 5 deg the guard snaps instead (and a
    // flap is kept joined, CutOptions::wedge_min_deg).
    EXPECT_EQ(wedges, 0) << "seed " << seed;
  }
  {
    // The built-in thigh (18 deg uncut): 5 deg after 100 random sweeps.
    Scene thigh = make_thigh_scene();
    thigh.scalpel.shape_guard_deg = 5;
    Simulation sim(thigh);
    RandomStrokes random(20261122);
    for (int k = 0; k < 100; ++k) {
      sim.cut_along(random.next(thigh.operation_region.sphere.center, 0.02, 0.03, 0.5));
      ASSERT_GE(operation_min_dihedral(sim), 5.0 - 1e-6) << "thigh, sweep " << k;
    }
    std::printf("shape guard, thigh: %d tets, operation part min dihedral %.2f deg\n",
                sim.counts().tets, operation_min_dihedral(sim));
  }
  // Without it, and at 1 deg (the default until stop 51), the same first seed: the thin tets
  // the 5 deg guard prevents, and the floor 1 deg keeps (the lowest after any stroke: the smoothing
  // and flips of later strokes may raise the last one). Last, the default guard with nothing to
  // keep flaps joined (CutOptions::wedge_min_deg = 0): the wedges that option prevents.
  struct Case {
    double guard;
    bool flaps_kept_joined;
  };
  for (const Case c : {Case{0.0, true}, Case{1.0, true}, Case{1.0, false}}) {
    const double guard = c.guard;
    Scene plain_scene = scene;
    plain_scene.scalpel.shape_guard_deg = guard;
    SimulationOptions options;
    if (!c.flaps_kept_joined) options.cut.wedge_min_deg = 0;
    Simulation plain(plain_scene, options);
    std::mt19937 rng(1u);
    double lowest = 180;
    for (int k = 0; k < 100; ++k) {
      plain.cut_along(random_liver_stroke(rng, centre));
      lowest = std::min(lowest, operation_min_dihedral(plain));
    }
    const int wedges = test::sharp_wedges(plain.mesh());
    std::printf(
        "guard %.0f deg%s, seed 1: min dihedral %.2f deg (lowest after a stroke %.2f), %d "
        "tets under 5 deg, %d wedges under 5 deg\n",
        guard, c.flaps_kept_joined ? "" : " (flaps not kept joined)", operation_min_dihedral(plain),
        lowest, thin_operation_tets(plain), wedges);
    EXPECT_GT(thin_operation_tets(plain), 50) << "guard " << guard;
    // Where a stroke's wall meets an earlier wall or the skin at under 5 deg, the tet between
    // them would become a flap with two surface faces at that angle; no repair after the stroke
    // can lift it (docs/DESIGN.md section 8 "Where bisection stops" (d)). Kept joined across
    // one of them, none is left at 1 deg (stop 50; 6 without). With no guard at all one is (a
    // split's sliver that a later stroke opens beside; stop 51).
    if (c.flaps_kept_joined)
      EXPECT_LE(wedges, guard > 0 ? 0 : 1) << "guard " << guard;
    else
      EXPECT_GT(wedges, 0) << "guard " << guard << ", flaps not kept joined";
    EXPECT_LT(operation_min_dihedral(plain), 2.0) << "guard " << guard;
    if (guard > 0) {
      EXPECT_GE(lowest, guard - 1e-6);
    } else {
      EXPECT_LT(lowest, 1.0);
    }
  }
}

// The live setter (dynamic_reconfigure's shape_guard_deg): values outside [0, 30] degrees, or not
// a number, are refused with the key named and leave the guard as it was.
TEST(SimulationRandomCuts, ShapeGuardSetterRefusesOutOfRange) {
  Simulation sim(make_thigh_scene());
  EXPECT_EQ(sim.scene().scalpel.shape_guard_deg, 5.0);  // the scene's default
  for (const double bad : {-1.0, 30.5, std::nan("")}) {
    try {
      sim.set_shape_guard_deg(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("shape_guard_deg"), std::string::npos) << e.what();
    }
    EXPECT_EQ(sim.scene().scalpel.shape_guard_deg, 5.0) << "after " << bad;
  }
  sim.set_shape_guard_deg(0);
  EXPECT_EQ(sim.scene().scalpel.shape_guard_deg, 0.0);
  sim.set_shape_guard_deg(30);
  EXPECT_EQ(sim.scene().scalpel.shape_guard_deg, 30.0);
  sim.reset();  // back to the scene's, as the cut pressure is
  EXPECT_EQ(sim.scene().scalpel.shape_guard_deg, 5.0);
}

// The same property on the organ-scale TetGen liver (config/scenes/liver2_surface.yaml, 56k
// tets tetrahedralized from config/meshes/sofa_liver2.obj, hanging from its left lobe): 40
// seeded strokes in CI (each costs ~1.5 s here: organ-scale re-assembly and refactorization per
// cut, see issue 10), TISSUE_RANDOM_CUT_STROKES=1000 or 10000 (./tissue test --strokes N) for the
// nightly sizes. When the operation part is cut to pieces the strokes go on: every later cut must
// keep the same properties. The Cholesky SPD check runs every 10th stroke (it dominates the run
// time); the other checks after every stroke.
TEST(SimulationRandomCuts, TetGenLiverStrokesKeepSpec6AndAnSpdSystem) {
  const int strokes = stroke_count(40);
  ASSERT_GT(strokes, 0) << "TISSUE_RANDOM_CUT_STROKES must be a positive number";
  const Scene scene =
      load_scene(std::string(TISSUE_TEST_DATA_DIR) + "/../../config/scenes/liver2_surface.yaml");
  Simulation sim(scene);
  RandomStrokes random(20261123);
  const double r = scene.operation_region.sphere.radius;
  // The liver hangs from its left lobe and sags; the blade cuts where the tissue IS, so the
  // strokes go around the sagged operation region (its centre moved by the nearest node's
  // displacement).
  Vec3 centre = scene.operation_region.sphere.center;
  {
    const Eigen::VectorXd u = sim.full_displacement();
    int nearest = 0;
    for (int i = 1; i < sim.mesh().num_nodes(); ++i)
      if ((sim.mesh().nodes[i] - centre).norm() < (sim.mesh().nodes[nearest] - centre).norm())
        nearest = i;
    centre += u.segment<3>(3 * nearest);
  }
  const int cuts = run_random_strokes(sim, random, strokes, centre, 0.8 * r, 0.8 * r, 0.0, 10);
  std::printf("liver random sweeps: %d of %d cut, %d tets split, %d tets, %d free pieces held\n",
              cuts, strokes, sim.counts().tets_split, sim.counts().tets,
              sim.counts().free_pieces_held);
  EXPECT_GT(cuts, strokes / 4);
}

}  // namespace
}  // namespace stc

namespace stc {
namespace {

// What `./tissue soak` does to the node (scripts/soak_driver.py), in lockstep and seeded, so a
// failure it finds can be replayed: a random-walk scalpel around the operation region (steps of
// r/100, pulled back within 1.3 r, a random-walk orientation), every 500 steps a burst of 20
// service actions (cutting enabled, or a straight ~cut path of 2, 10 or 200 poses with the
// identity orientation, inserted between the walk's steps as the node
// slices it: one to three sweeps before a step), a reset every 6,000 steps. While a cut step
// runs the node's walk goes on in real time: after a step that cut, the blade advances 30 walk
// increments at once. After every step:
// a converged, finite solve; after every cut, an SPD free block. Scene and length:
// TISSUE_SOAK_REPLICA_SCENE (a scene file; default the built-in thigh) and
// TISSUE_SOAK_REPLICA_STEPS (default 3,000), seed TISSUE_SOAK_REPLICA_SEED (default 12).
TEST(SimulationRandomCuts, SoakReplicaKeepsAConvergedSpdSystem) {
  const char* scene_env = std::getenv("TISSUE_SOAK_REPLICA_SCENE");
  const char* steps_env = std::getenv("TISSUE_SOAK_REPLICA_STEPS");
  const Scene scene = scene_env ? load_scene(scene_env) : make_thigh_scene();
  const long steps = steps_env ? std::atol(steps_env) : 3000;
  ASSERT_GT(steps, 0) << "TISSUE_SOAK_REPLICA_STEPS must be a positive number";
  ASSERT_EQ(scene.operation_region.kind, OperationRegion::Kind::kSphere);
  // The anchor rule must hold every piece itself: a piece the factor had to find (a WARN or an
  // ERROR from the simulation) is a miss, reported with the step.
  std::vector<std::string> misses;
  long k = 0;
  SimulationOptions options;
  options.log = [&misses, &k](LogLevel level, const std::string& message) {
    if (level != LogLevel::kInfo) misses.push_back("step " + std::to_string(k) + ": " + message);
  };
  Simulation sim(scene, options);
  const Vec3 c = scene.operation_region.sphere.center;
  const double r = scene.operation_region.sphere.radius;
  const char* seed_env = std::getenv("TISSUE_SOAK_REPLICA_SEED");
  std::mt19937 rng(seed_env ? static_cast<unsigned>(std::atol(seed_env)) : 12u);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Vec3 p = c;
  Eigen::Vector4d q(0, 0, 0, 1);
  const auto walk = [&] {
    p += std::max(r / 100, 1e-4) * Vec3(gauss(rng), gauss(rng), gauss(rng));
    if ((p - c).norm() > 1.3 * r) p = c + (p - c) * 1.3 * r / (p - c).norm();
    for (int k = 0; k < 4; ++k) q[k] += 0.01 * gauss(rng);
    q.normalize();
  };
  std::vector<std::vector<BladePose>> queued;
  std::optional<PathCut> active;
  int cut_steps = 0, path_cuts = 0, resets = 0;
  for (k = 0; k < steps; ++k) {
    if (k > 0 && k % 6000 == 0) {
      sim.reset();
      queued.clear();
      active.reset();
      ++resets;
    }
    if (k % 500 == 250)
      for (int action = 0; action < 20; ++action) {
        if (rng() % 2 == 0) {
          sim.set_cutting_enabled(true);
          continue;
        }
        const Vec3 a = c + r * Vec3(unit(rng), unit(rng), unit(rng));
        const Vec3 b = a + r * Vec3(unit(rng), unit(rng), unit(rng));
        const int n = std::array<int, 3>{2, 10, 200}[rng() % 3];
        std::vector<BladePose> path(static_cast<size_t>(n));
        for (int s = 0; s < n; ++s)
          path[static_cast<size_t>(s)].position = a + s * (b - a) / (n - 1);
        queued.push_back(std::move(path));
      }
    bool path_cut = false;
    if (!active && !queued.empty()) {
      active = sim.begin_path_cut(queued.front());
      queued.erase(queued.begin());
    }
    // The node's slice lasts up to 40 % of a period: one to three sweeps before a step.
    for (int sweeps = 1 + static_cast<int>(rng() % 3); sweeps > 0 && active && !active->done();
         --sweeps) {
      sim.cut_path_slice(*active, std::chrono::steady_clock::time_point{});
      path_cut = true;
    }
    walk();
    BladePose blade;
    blade.position = p;
    blade.orientation = Eigen::Quaterniond(q[3], q[0], q[1], q[2]);
    blade.t = static_cast<double>(k) / 100;
    const StepStats s = sim.step(blade);
    if (active && active->done()) {
      sim.finish_path_cut(*active);
      active.reset();
      ++path_cuts;
    }
    cut_steps += s.cutting;
    if (s.cutting || path_cut)
      for (int i = 0; i < 30; ++i) walk();
    if (s.cutting || path_cut) {
      InvariantLimits limits;
      limits.initial_volume = sim.counts().volume_initial;
      const auto violated = check_cut_invariants(sim.mesh(), sim.tet_size_classes(), limits);
      ASSERT_TRUE(violated.empty()) << "step " << k << ": " << violated.front();
    }
    // The SPD check (a sparse Cholesky of the free block, free pieces found again) costs more
    // than an organ-scale step: after every cut on small scenes, on failure on the others.
    if (!s.converged || ((s.cutting || path_cut) && sim.counts().tets < 20000)) {
      ASSERT_NO_THROW(SparseCholesky{free_block(sim)}) << "step " << k << ": not SPD";
    }
    ASSERT_TRUE(s.converged) << "step " << k << " (" << cut_steps << " cut steps, " << path_cuts
                             << " paths, " << resets << " resets): " << solve_diagnosis(sim);
    ASSERT_TRUE(sim.model().displacement().allFinite()) << "step " << k;
    ASSERT_TRUE(misses.empty()) << misses.front();
    if ((k + 1) % 1000 == 0) {
      std::printf("soak replica: %ld steps, %d cut steps, %d paths, %d tets, %d free pieces\n",
                  k + 1, cut_steps, path_cuts, sim.counts().tets, sim.counts().free_pieces_held);
      std::fflush(stdout);
    }
  }
  std::printf("soak replica: %ld steps, %d cut steps, %d paths, %d resets\n", steps, cut_steps,
              path_cuts, resets);
  EXPECT_GT(cut_steps + path_cuts, 0);
}

}  // namespace
}  // namespace stc
