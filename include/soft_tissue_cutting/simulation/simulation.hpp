// One simulated surgical scene: the per-step pipeline of docs/DESIGN.md section 10 (collision,
// contact, cutting, hybrid solve, surface recovery) behind a ROS-free facade. The ROS node
// and the offline `./tissue solve` both drive this class.
#pragma once

#include "soft_tissue_cutting/cutting/cut_result.hpp"  // CutOptions
#include "soft_tissue_cutting/gpu/gl_context_options.hpp"
#include "soft_tissue_cutting/mesh/boundary_surface.hpp"
#include "soft_tissue_cutting/scene/scene.hpp"
#include "soft_tissue_cutting/simulation/model_counts.hpp"      // ModelCounts
#include "soft_tissue_cutting/simulation/surface_snapshot.hpp"  // DeformedSurface

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace stc {

class HybridModel;
struct RegionMoveStats;  // simulation/region_move_stats.hpp
struct StepTimes;        // simulation/step_times.hpp
class DeformedToRest;    // cutting/rest_mapping.hpp

// The core's log sink: where Simulation sends its messages (a free piece held, ...). The core
// never writes to stderr itself: `tissue solve` prints them, tissue_node routes them to
// rosconsole (so they reach /rosout). Empty: dropped.
enum class LogLevel { kInfo, kWarn, kError };
using LogSink = std::function<void(LogLevel level, const std::string& message)>;

struct SimulationOptions {
  std::optional<Backend> backend;  // nullopt: the scene's solver.backend
  GlContextOptions gl;             // the gl backend's context and shader folder
  LogSink log;
  // `follow` region: a move requested at one step is awaited at the start of the next
  // (offline: deterministic, every run moves at the same steps). Off (online), the old model
  // runs until the worker has finished and the loop never blocks.
  bool wait_for_region_moves = false;
  // `follow` region, online: the sweeps that waited for a move are cut for about this long
  // per step (ms; another run of them only while the step's runs so far, at their average
  // cost, leave room for it; the rest wait for the next steps), so a step after a swap does
  // not cut the whole backlog at once (docs/DESIGN.md section 10a, "Swap"): half the organ-scale
  // 10 ms step, the rest for the step's solve. Offline (wait_for_region_moves) every waiting
  // sweep is cut at once.
  double waiting_cut_budget_ms = 5.0;
  // Organ-scale meshes refactor a grown frame ahead on a second thread (docs/DESIGN.md section
  // 6.2, "Refactored ahead"). On, the next cut awaits that factor (offline: deterministic, every
  // run solves with the same factors); off (online), a cut takes it once it is ready and the
  // loop never waits for it (the solutions differ by rounding only).
  bool wait_for_factor_ahead = false;
  // The cutter's options (docs/DESIGN.md section 8); the defaults are what it describes. Tests
  // switch a stage off to measure what it does (e.g. insert_nodes). Except the shape guard
  // (split_min_dihedral_deg): the scene's ScalpelParams::shape_guard_deg replaces it.
  CutOptions cut;
};

// Stage timings and outcome of one step.
struct StepStats {
  std::uint64_t step = 0;
  bool in_contact = false;
  bool cutting = false;  // this step inserted a cut
  // Of which: the end of a stroke, conformed and opened (finish_stroke, on the step after the
  // blade's last cut; cutting/cut_sweep.hpp). That step may hold the blade still.
  bool stroke_finished = false;
  Vec3 contact_force = Vec3::Zero();   // N, reaction of the tissue on the blade (scene frame)
  Vec3 contact_torque = Vec3::Zero();  // N m, its moment about the blade tip (scene frame)
  std::vector<int> contact_nodes;      // the nodes the blade holds this step, ascending
  std::vector<Vec3> contact_points;    // where it holds them (deformed, scene frame)
  int cg_iterations = 0;
  double residual = 0;
  bool converged = true;
  // The backend that solved this step ("cpu" or "gl"; empty: nothing to solve). A gl solve
  // that float32 could not finish is completed on the cpu: solved_by "cpu" and
  // fallback_reason says why in one line.
  std::string solved_by;
  std::string fallback_reason;
  std::string solver_message;      // one line when !converged: why the solve stopped short
  int tets_split = 0;              // this step
  int nodes_added = 0;             // this step
  bool reached_interface = false;  // the blade tried to cut into the condensed part
  // `follow` region: a re-condensation runs on the worker after this step (the cut waits),
  // or this step swapped the moved region's model in (region_follower.hpp).
  bool region_moving = false, region_moved = false;
  // `follow` region, online: how far the cut lags behind the blade after this step - the
  // sweeps still waiting to be cut (for a move, or for the next steps' cutting budget,
  // SimulationOptions::waiting_cut_budget_ms) and the blade's travel over them (m).
  int sweeps_waiting = 0;
  double cut_lag = 0;
  // No recovery_ms: a step never recovers the condensed surface (surface() does, on demand).
  double collision_ms = 0, cutting_ms = 0, assembly_ms = 0, solve_ms = 0;
  double step_ms = 0;
};

struct CutOutcome {
  bool success = false;
  std::string message;
  int tets_split = 0, nodes_added = 0, cut_faces = 0;
};

// A cut path being inserted a slice at a time (begin_path_cut, cut_path_slice,
// finish_path_cut), so a caller can keep stepping between the slices of a long path; the ROS
// node does, and cut_along() is the three in one go plus a solve.
struct PathCut {
  std::string refusal;           // set: the path was refused (done() at once)
  std::vector<BladePose> poses;  // the path resampled at a fixed spacing (cutting/blade_path)
  std::size_t next = 1;          // the next sweep is poses[next - 1] -> poses[next]
  int faces_before = 0;
  int tets_split = 0, nodes_added = 0;
  bool changed = false;  // some sweep changed the mesh
  // Some pose of the blade edge lay in the operation part (`follow`: in the tissue, which the
  // region moves to).
  bool crossed = false;
  bool reached_interface = false;  // cut faces dropped at the interface of the condensed part
  // The deformation when the path was begun: every sweep of the path is carried to rest
  // coordinates through it, so the cut does not depend on how many steps (each a solve) run
  // between slices - the path is where the tissue was when the cut was asked for. A fixed
  // region's covers the operation part; a `follow` region's the whole tissue (the region moves
  // along the path).
  std::shared_ptr<const DeformedToRest> to_rest;
  bool done() const { return !refusal.empty() || next >= poses.size(); }
};

class Simulation {
 public:
  explicit Simulation(Scene scene, SimulationOptions options = {});
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // One step of docs/DESIGN.md section 10 with the blade at `blade` (scene frame), or no scalpel.
  StepStats step(const std::optional<BladePose>& blade);
  // Cut along consecutive poses regardless of cut_pressure (the ~cut service), then solve.
  CutOutcome cut_along(const std::vector<BladePose>& poses);
  // Validates (>= 2 finite poses) and resamples the path; a refused path comes back done()
  // with `refusal` set.
  PathCut begin_path_cut(const std::vector<BladePose>& poses) const;
  // Inserts the next sweeps of `cut` until `deadline` (at least one); no solve, so the next
  // step() (or cut_along's solve) brings the displacements to the new mesh.
  void cut_path_slice(PathCut& cut, std::chrono::steady_clock::time_point deadline);
  // Counts of the finished (or refused) cut and the true reason when nothing was cut.
  CutOutcome finish_path_cut(const PathCut& cut) const;
  // Spacing (m) at which cut paths are resampled: 0.3 of the median edge of the initial
  // operation part (simulation.cpp, kPathSpacingFraction).
  double cut_path_spacing() const;
  // Back to the initial mesh and state, identical to a fresh start.
  void reset();

  void set_cutting_enabled(bool enabled);
  bool cutting_enabled() const;
  void set_cut_pressure(double newtons);
  // The cutter's shape guard (degrees in [0, 30]; 0: off; docs/DESIGN.md section 8 "Shape
  // guard"), from the next cut on; scene().scalpel.shape_guard_deg follows it. Throws
  // std::invalid_argument (and keeps the old value) outside that range.
  void set_shape_guard_deg(double degrees);
  // Homogeneous material: K scales with E, so K1 and K0 rescale without refactorising.
  void set_young_modulus(double pascal);

  const Scene& scene() const;
  const TetMesh& mesh() const;
  // The drawn surface now: surface_snapshot().compute(), its recovery kept by the model.
  DeformedSurface surface() const;
  // What surface() is computed from, copied (no solve): compute() it later on any thread,
  // e.g. outside the lock the caller guards this Simulation with (surface_snapshot.hpp).
  SurfaceSnapshot surface_snapshot() const;
  // Hands the recovery a computed snapshot ran back to the model, so the next surface() or
  // full_displacement() need not solve for u_S again; ignored if the model was since replaced
  // (reset, region move) or rescaled. Cheap (copies).
  void adopt_recovery(const SurfaceSnapshot& computed);
  std::uint64_t surface_version() const;  // changes whenever the drawn surface changes
  // Changes whenever mesh() (topology or rest positions: mesh_hash) may have changed.
  std::uint64_t mesh_version() const;
  ModelCounts counts() const;
  const StepStats& last_stats() const;
  std::string backend() const;                    // solver actually in use: "cpu" or "gl"
  std::string renderer() const;                   // GL renderer for "gl"
  std::string backend_note() const;               // why gl fell back to cpu, if it did
  std::string backend_requested() const;          // "cpu" or "gl": the option, else the scene's
  std::vector<std::uint8_t> tet_regions() const;  // 1 = operation part, per tet
  std::vector<BladePose> blade_path() const;      // poses of the current scalpel stroke

  // Full displacement (3 x nodes), interior condensed nodes recovered (for output).
  Eigen::VectorXd full_displacement();
  // docs/SCENE.md "Offline run" outputs. Throw std::runtime_error with a one-line reason.
  void write_vtk(const std::string& path);
  // `steps`: the step times for `step_ms`; nullptr = every step since the start (or reset).
  void write_stats_json(const std::string& path, double total_ms, const StepTimes* steps = nullptr);
  std::string stats_json(double total_ms, const StepTimes* steps = nullptr);
  // Wall time of every step() since the start (or the last reset), by kind.
  const StepTimes& step_times() const;
  // Precompute stage timings of the condensation (ms), as the hybrid model measured them.
  const std::map<std::string, double>& precompute_timings_ms() const;
  // The hybrid model behind the simulation (read-only: for tests and analysis).
  const HybridModel& model() const;
  // Per tet: the volume of the input tet it descends from (its size class, docs/SCENE.md "Cut
  // invariants").
  const std::vector<double>& tet_size_classes() const;
  // `follow` region: moves so far, their durations, the ball now (nullptr for a fixed region).
  const RegionMoveStats* region_moves() const;
  // Waits for a running region move, swaps it in and cuts the sweeps that waited for it
  // (moving again, waiting, as they need): offline callers, tests.
  void settle_region_move();
  // Hash of the current mesh topology and rest positions (replays must agree).
  std::string mesh_hash() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stc
