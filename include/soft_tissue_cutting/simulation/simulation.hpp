// One simulated surgical scene: the per-step pipeline of METHOD.md section 5 (collision,
// contact, cutting, hybrid solve, surface recovery) behind a ROS-free facade. The ROS node
// and the offline `./tissue solve` both drive this class.
#pragma once

#include "soft_tissue_cutting/mesh/boundary_surface.hpp"
#include "soft_tissue_cutting/scene/scene.hpp"

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace stc {

class HybridModel;

struct SimulationOptions {
  std::string backend;  // "" = the scene's solver.backend; "cpu" or "gl"
};

// Stage timings and outcome of one step.
struct StepStats {
  std::uint64_t step = 0;
  bool in_contact = false;
  bool cutting = false;          // this step inserted a cut
  Vec3 contact_force = Vec3::Zero();  // N, reaction of the tissue on the blade (scene frame)
  Vec3 contact_torque = Vec3::Zero();  // N m, its moment about the blade tip (scene frame)
  std::vector<int> contact_nodes;      // the nodes the blade holds this step, ascending
  std::vector<Vec3> contact_points;    // where it holds them (deformed, scene frame)
  int cg_iterations = 0;
  double residual = 0;
  bool converged = true;
  int tets_split = 0;   // this step
  int nodes_added = 0;  // this step
  bool reached_interface = false;  // the blade tried to cut into the condensed part
  double collision_ms = 0, cutting_ms = 0, assembly_ms = 0, solve_ms = 0, recovery_ms = 0;
  double step_ms = 0;
};

// Sizes of the current state (after cuts), as SPEC section 4 names them.
struct ModelCounts {
  int nodes = 0, tets = 0, dof_operation = 0, nodes_interface = 0;
  int nodes_surface_condensed = 0, nodes_interior_condensed = 0;
  int cuts = 0, tets_split = 0, free_pieces_held = 0;
  long cg_iterations_total = 0;  // every CG iteration since the start (or the last reset)
  double volume_initial = 0, volume_final = 0;
};

struct CutOutcome {
  bool success = false;
  std::string message;
  int tets_split = 0, nodes_added = 0, cut_faces = 0;
};

// The visible deformed surface: operation-part surface including cut faces, plus the
// condensed surface S (METHOD 5 step 6).
struct DeformedSurface {
  std::vector<Vec3> positions;        // deformed position of every mesh node
  std::vector<double> displacement;   // |u| per node, m
  std::vector<BoundaryTriangle> triangles;
};

class Simulation {
 public:
  explicit Simulation(Scene scene, SimulationOptions options = {});
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // One step of METHOD 5 with the blade at `blade` (scene frame), or no scalpel.
  StepStats step(const std::optional<BladePose>& blade);
  // Cut along consecutive poses regardless of cut_pressure (the ~cut service), then solve.
  CutOutcome cut_along(const std::vector<BladePose>& poses);
  // Back to the initial mesh and state, identical to a fresh start.
  void reset();

  void set_cutting_enabled(bool enabled);
  bool cutting_enabled() const;
  void set_cut_pressure(double newtons);
  // Homogeneous material: K scales with E, so K1 and K0 rescale without refactorising.
  void set_young_modulus(double pascal);

  const Scene& scene() const;
  const TetMesh& mesh() const;
  DeformedSurface surface() const;
  std::uint64_t surface_version() const;  // changes whenever the drawn surface changes
  ModelCounts counts() const;
  const StepStats& last_stats() const;
  std::string backend() const;   // solver actually in use: "cpu" or "gl"
  std::string renderer() const;  // GL renderer for "gl"
  std::string backend_note() const;  // why gl fell back to cpu, if it did
  std::vector<std::uint8_t> tet_regions() const;  // 1 = operation part, per tet
  std::vector<BladePose> blade_path() const;       // poses of the current scalpel stroke

  // Full displacement (3 x nodes), interior condensed nodes recovered (for output).
  Eigen::VectorXd full_displacement();
  // SPEC section 4 outputs. Throw std::runtime_error with a one-line reason.
  void write_vtk(const std::string& path);
  void write_stats_json(const std::string& path, double total_ms);
  std::string stats_json(double total_ms);
  // Precompute stage timings of the condensation (ms), as the hybrid model measured them.
  const std::map<std::string, double>& precompute_timings_ms() const;
  // The hybrid model behind the simulation (read-only: for tests and analysis).
  const HybridModel& model() const;
  // Per tet: the volume of the input tet it descends from (its size class, SPEC 6).
  const std::vector<double>& tet_size_classes() const;
  // Hash of the current mesh topology and rest positions (replays must agree).
  std::string mesh_hash() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stc
