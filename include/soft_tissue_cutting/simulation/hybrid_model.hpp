// The hybrid condensed finite element model (docs/DESIGN.md sections 3-5): the operation part
// (part 1) stays a sparse FE model that cutting may change; the non-operation part (part 2) is
// condensed once onto the interface. Each step solves docs/DESIGN.md eq. (10) (the paper's eq. 17)
// over the free DOFs of O u I,
//   [K1_OO  K1_OI     ] [u_O]   [f_O     ]
//   [K1_IO  K1_II + K0] [u_I] = [f_I - g0]
// with the injectable LinearSolver (projected CG, warm-started). The condensed part's
// displacements u_S, u_Q follow from u_I through the kept factor of K2_NN, on demand.
// ROS-free; the Simulation facade drives it.
#pragma once

#include "soft_tissue_cutting/assembly/element_cache.hpp"
#include "soft_tissue_cutting/condensation/condensed_part.hpp"
#include "soft_tissue_cutting/cutting/cut_result.hpp"  // NewNode: how the cutting stage adds nodes
#include "soft_tissue_cutting/partition/partition.hpp"
#include "soft_tissue_cutting/recovery/surface_recovery.hpp"
#include "soft_tissue_cutting/scene/scene.hpp"
#include "soft_tissue_cutting/simulation/model_counts.hpp"  // HybridModelCounts
#include "soft_tissue_cutting/solve/linear_solver.hpp"

#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace stc {

// Imposed displacements: node -> displacement (scalpel contact, held free pieces).
using ImposedDisplacements = std::map<int, Vec3>;

class HybridModel {
 public:
  // Partition, element matrices, condensation (CHOLMOD), recovery operator, hybrid matrix.
  // Throws std::runtime_error if part 2 cannot be condensed (singular K2_NN).
  explicit HybridModel(const Scene& scene,
                       std::unique_ptr<LinearSolver> solver = make_cpu_solver());
  // The same tissue as `from` (its current mesh with every cut, loads, fixed nodes, material
  // and element matrices, re-used as they are), re-partitioned: part 1 = the tets with
  // operation_tet[t] != 0, part 2 condensed afresh (a condensed part may hold cut geometry).
  // Reads only what solve() never writes (mesh, loads, fixed nodes, element matrices), so it
  // may run on a worker thread while `from` keeps solving (simulation/region_follower.hpp).
  // Starts at zero displacement: set_displacement() hands the current state over.
  // held_nodes: as set_held_nodes, but set before the hybrid matrix is first factored (a held
  // free piece makes that matrix singular: the factor must leave its DOFs out from the start).
  // expected_cut_nodes: where the next cut is expected (the blade's waiting sweep): the first
  // factorization frames their rows (LinearSolver::History::expected_rows), so that cut
  // refactors a frame, not the whole hybrid matrix.
  HybridModel(const HybridModel& from, std::vector<std::uint8_t> operation_tet,
              const std::vector<int>& held_nodes = {},
              std::unique_ptr<LinearSolver> solver = make_cpu_solver(),
              const std::vector<int>& expected_cut_nodes = {});
  ~HybridModel();
  HybridModel(const HybridModel&) = delete;
  HybridModel& operator=(const HybridModel&) = delete;

  // One quasi-static step: the imposed DOFs become constrained DOFs of the projected CG, warm
  // started from the current displacement. Imposed nodes must be O or I nodes
  // (std::invalid_argument otherwise); imposed components on fixed nodes are ignored. With
  // the system and the imposed displacements unchanged since the last solve, the last
  // solution is returned at once (0 iterations): it is still exact.
  CgResult solve(const ImposedDisplacements& imposed = {});

  // Sum over `nodes` of (K u - f) of the whole model at the current solution: the force the
  // imposing body (blade, holder) must apply to the tissue; the tissue pushes back on it with
  // the negative. On O and I nodes this is the hybrid residual (for I nodes K0 u_I + g0 is
  // exactly part 2's K2_II u_I + K2_IN u_N - f2_I). Fixed DOFs and S/Q nodes contribute 0.
  Vec3 reaction_force(const std::vector<int>& nodes) const;

  // 3n displacement, every node current: O and I from the last solve, S and Q recovered
  // from u_I through the factor of K2_NN when u_I moved since the last recovery (one sparse
  // solve, at the rate the caller asks: display, output).
  const Vector& displacement() const;
  // O and I current; S and Q as last recovered (the per-step contact and cutting use this).
  const Vector& operation_displacement() const { return u_; }
  // displacement() to be recovered later, on any thread, without this model: u copied and
  // the condensed part shared (recovery/surface_recovery.hpp). Cheap: no solve.
  DisplacementSnapshot displacement_snapshot() const;
  // Takes over the S and Q entries of a recovered snapshot of this model, so displacement()
  // need not solve them again; ignored if the snapshot is not recovered or was taken through
  // another condensation or stiffness (a replaced model, a new E). Touches only the recovery
  // cache displacement() fills.
  void adopt_recovery(const DisplacementSnapshot& recovered) const;
  // Kept for callers of the former two-stage recovery: displacement() recovers Q too.
  void recover_interior();
  // How many recoveries of u_S, u_Q ran (for tests and benchmarks).
  long recoveries() const { return recoveries_; }
  // Takes over a displacement of the same mesh (3n, e.g. of the model this one replaces): the
  // next solve runs, warm from it.
  void set_displacement(const Vector& u);
  // Zero displacement everywhere (the next solve starts cold).
  void reset_displacement();

  // Cutting hook: the operation part of mesh_for_cutting() was changed in place (tets
  // replaced or appended, nodes appended). changed_tets: indices of replaced and new tets
  // (all become operation tets); new_nodes: one entry per appended node, in order (all become
  // O nodes, unloaded; an edge node starts at (1 - t) u_a + t u_b and is fixed only if both
  // ends are; a duplicate starts at u_a and keeps a's fixed flag). Only the changed element
  // matrices are recomputed; K0, g0, R, c_S are untouched. Consistent gravity of the changed tets
  // is re-lumped.
  void update_operation_part(const std::vector<int>& changed_tets,
                             const std::vector<NewNode>& new_nodes);
  TetMesh& mesh_for_cutting() { return mesh_; }

  // Homogeneous material: K1 and K0 scale with E, c_S with 1/E, g0 and R are unchanged
  // (K2_NN^-1 K2_NI and K2_IN K2_NN^-1 f_N are ratios), no refactorization.
  void set_young_modulus(double young_modulus);

  // Nodes held in place in every solve until changed (free pieces, simulation.cpp): the solver
  // builds its preconditioner without their DOFs (LinearSolver::set_matrix). A copy made of a
  // held node by a cut is held too. The solver is set up again (at first use) only when the set
  // changes.
  void set_held_nodes(const std::vector<int>& nodes);
  // Where the next cut is expected (nodes): a factorization that cannot take its matrix
  // through the last frame (held nodes changed the rows) frames their rows instead
  // (LinearSolver::History::expected_rows, docs/DESIGN.md section 6.2). Forgotten at the next
  // factor refresh.
  void expect_cut_near(std::vector<int> nodes) { expected_cut_nodes_ = std::move(nodes); }

  void set_solver(std::unique_ptr<LinearSolver> solver);
  // The solver, set up (factored) for the current matrix and held nodes.
  const LinearSolver& solver() const {
    refresh_factor();
    return *solver_;
  }
  // New settings: the next solve runs even if nothing else changed (a tighter tolerance).
  void set_cg_settings(const CgSettings& settings) {
    settings_ = settings;
    system_changed_ = true;
  }
  const CgSettings& cg_settings() const { return settings_; }

  const TetMesh& mesh() const { return mesh_; }
  const Partition& partition() const { return partition_; }
  const Material& material() const { return elements_.material(); }
  HybridModelCounts counts() const;
  const CgResult& last_result() const { return last_; }
  // Precompute stages in ms: partition, element_stiffness, condensation_assembly,
  // condensation_factor, condensation_solve, condensation_products, hybrid_assembly, total.
  const std::map<std::string, double>& precompute_timings_ms() const { return timings_; }

  // The assembled hybrid system (docs/DESIGN.md eq. (10)) and its DOF numbering (for tests and GPU
  // backends).
  const SparseMatrix& hybrid_matrix() const { return a_; }
  const Vector& hybrid_rhs() const { return b_; }
  const DofMap& hybrid_dofs() const { return dofs_; }
  // Global load vector (3n): point loads + consistent gravity of the current mesh.
  Vector loads() const;
  const std::vector<std::uint8_t>& fixed_nodes() const { return fixed_; }
  const std::vector<std::uint8_t>& held_nodes() const { return held_; }  // set_held_nodes

 private:
  void condense_and_assemble(std::chrono::steady_clock::time_point start);
  // The hybrid system (10) of the current mesh and partition. With `changed` (the tets a cut
  // changed) and `removed` (their contributions as last assembled, negated, by global DOF), a_
  // is updated by the difference instead of re-assembled when the DOFs kept their rows.
  void rebuild_hybrid_system(const std::vector<int>* changed = nullptr,
                             const std::vector<Triplet>* removed = nullptr);
  // a_ += the changed tets' new element matrices + `removed`; false if a_ cannot be updated.
  bool update_hybrid_matrix(const std::vector<int>& old_rows, const std::vector<int>& changed,
                            const std::vector<Triplet>& removed);
  std::vector<std::uint8_t> held_dofs() const;  // per hybrid row, from held_

  TetMesh mesh_;
  Vec3 gravity_ = Vec3::Zero();
  Vector point_loads_;               // 3n, new nodes unloaded
  Vector condensed_gravity_;         // gravity of part-2 tets (3n at construction)
  std::vector<std::uint8_t> fixed_;  // per node
  std::vector<std::uint8_t> held_;   // per node (set_held_nodes)
  ElementStiffnessCache elements_;
  Partition partition_;
  // Never changed once condensed (its dense K0 is dropped: k0_padded_ holds K0); shared with
  // displacement snapshots.
  std::shared_ptr<const CondensedPart> condensed_;
  double condensed_scale_ = 1.0;    // E now / E at condensation time
  DofMap dofs_;                     // hybrid system over free DOFs of O u I
  std::vector<int> interface_row_;  // free interface DOF k -> hybrid row
  SparseMatrix a_;
  SparseMatrix spare_;               // the last a_, whose arrays the next cut's update reuses
  std::vector<Tet> assembled_tets_;  // every tet's nodes as a_ holds its element matrix
  SparseMatrix k0_padded_;           // K0 as a sparse block (3|I|_free square), at the current E
  Vector b_;
  // u_ is mutable for the on-demand recovery of its S and Q entries in displacement().
  mutable Vector u_;
  mutable Vector recovered_from_;        // u_I the S and Q entries were recovered from
  mutable bool condensed_stale_ = true;  // u_I moved since then
  mutable long recoveries_ = 0;
  bool system_changed_ = true;  // matrix, rhs or u_ changed since the last solve
  // The solver has not seen the current matrix or held set yet (set up at first use).
  mutable bool factor_stale_ = false;
  // The DOFs (global_of) of the matrix the solver last saw: a cut keeps them and appends its
  // new nodes', so the solver may refactor only what changed (LinearSolver::History).
  mutable std::vector<int> solver_dofs_;
  // The rows a_ changed in since the solver last saw it (cuts' matrix updates); none: unknown
  // (a full assembly), the solver compares.
  mutable std::optional<std::vector<int>> rows_changed_;
  // The constructor's expected_cut_nodes, until the first factorization frames their rows.
  mutable std::vector<int> expected_cut_nodes_;
  void refresh_factor() const;
  ImposedDisplacements last_imposed_;
  std::unique_ptr<LinearSolver> solver_;
  CgSettings settings_;
  CgResult last_;
  std::map<std::string, double> timings_;
};

}  // namespace stc
