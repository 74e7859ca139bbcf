#include "soft_tissue_cutting/simulation/hybrid_model.hpp"

#include "soft_tissue_cutting/assembly/loads.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace stc {
namespace {

// One flag per mesh node: 1 for the held ones (HybridModel::set_held_nodes).
std::vector<std::uint8_t> held_flags(const TetMesh& mesh, const std::vector<int>& nodes) {
  std::vector<std::uint8_t> held(static_cast<size_t>(mesh.num_nodes()), 0);
  for (int n : nodes) {
    if (n < 0 || n >= mesh.num_nodes())
      throw std::invalid_argument("HybridModel: held node " + std::to_string(n) + " out of range");
    held[static_cast<size_t>(n)] = 1;
  }
  return held;
}

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Consistent gravity (rho g V / 4 per node, as gravity_loads) of the listed tets only, into f.
void add_gravity_of(const TetMesh& mesh, const std::vector<int>& tets, double density,
                    const Vec3& gravity, Vector& f) {
  if (gravity.isZero(0.0)) return;
  for (int t : tets) {
    const Vec3 share = density * tet_volume(mesh, t) / 4.0 * gravity;
    for (int n : mesh.tets[static_cast<size_t>(t)]) f.segment<3>(3 * n) += share;
  }
}

// a = K1 + K0 with K0 (dense, ni x ni, row-major) on the leading rows and columns: one merge
// of sorted rows into a's compressed arrays. Rows below ni are K1's as they are.
void merge_k0(const SparseMatrix& k1, const SparseMatrix& k0, SparseMatrix& a) {
  const int n = static_cast<int>(k1.rows()), ni = static_cast<int>(k0.rows());
  a.resize(n, n);
  a.resizeNonZeros(k1.nonZeros() + k0.nonZeros());  // an upper bound, trimmed below
  int* outer = a.outerIndexPtr();
  int* inner = a.innerIndexPtr();
  double* value = a.valuePtr();
  int out = 0;
  for (int r = 0; r < n; ++r) {
    outer[r] = out;
    const int* ki = k1.innerIndexPtr() + k1.outerIndexPtr()[r];
    const double* kv = k1.valuePtr() + k1.outerIndexPtr()[r];
    const int kn = k1.outerIndexPtr()[r + 1] - k1.outerIndexPtr()[r];
    int zi0 = 0, zn = 0;
    if (r < ni) zi0 = k0.outerIndexPtr()[r], zn = k0.outerIndexPtr()[r + 1] - zi0;
    const int* zi = k0.innerIndexPtr() + zi0;
    const double* zv = k0.valuePtr() + zi0;
    int i = 0, j = 0;
    while (i < kn || j < zn) {
      if (j >= zn || (i < kn && ki[i] < zi[j])) {
        inner[out] = ki[i], value[out++] = kv[i++];
      } else if (i >= kn || zi[j] < ki[i]) {
        inner[out] = zi[j], value[out++] = zv[j++];
      } else {
        inner[out] = ki[i], value[out++] = kv[i++] + zv[j++];
      }
    }
  }
  outer[n] = out;
  a.resizeNonZeros(out);
}

}  // namespace

HybridModel::HybridModel(const Scene& scene, std::unique_ptr<LinearSolver> solver)
    : mesh_(scene.mesh),
      gravity_(scene.gravity),
      point_loads_(point_loads(scene)),
      fixed_(fixed_node_mask(scene)),
      held_(scene.mesh.nodes.size(), 0),
      solver_(std::move(solver)) {
  if (!solver_) throw std::invalid_argument("HybridModel: no linear solver");
  settings_.tolerance = scene.solver.tolerance;
  settings_.max_iterations = scene.solver.max_iterations;
  const auto start = Clock::now();

  auto t0 = Clock::now();
  partition_ = partition_mesh(mesh_, scene.operation_region);
  timings_["partition"] = ms_since(t0);

  t0 = Clock::now();
  elements_ = ElementStiffnessCache(mesh_, scene.material);
  timings_["element_stiffness"] = ms_since(t0);
  condense_and_assemble(start);
}

HybridModel::HybridModel(const HybridModel& from, std::vector<std::uint8_t> operation_tet,
                         const std::vector<int>& held_nodes, std::unique_ptr<LinearSolver> solver,
                         const std::vector<int>& expected_cut_nodes)
    : mesh_(from.mesh_),
      gravity_(from.gravity_),
      point_loads_(from.point_loads_),
      fixed_(from.fixed_),
      held_(held_flags(from.mesh_, held_nodes)),
      elements_(from.elements_),  // at the current E: the new condensation is at scale 1
      solver_(std::move(solver)),
      settings_(from.settings_) {
  if (!solver_) throw std::invalid_argument("HybridModel: no linear solver");
  if (operation_tet.size() != static_cast<size_t>(mesh_.num_tets()))
    throw std::invalid_argument("HybridModel: one operation label per tet expected");
  const auto start = Clock::now();
  const auto t0 = Clock::now();
  partition_ = partition_from_labels(mesh_, std::move(operation_tet));
  timings_["partition"] = ms_since(t0);
  timings_["element_stiffness"] = 0;  // re-used from `from`
  expected_cut_nodes_ = expected_cut_nodes;
  condense_and_assemble(start);
}

void HybridModel::condense_and_assemble(Clock::time_point start) {
  // K0, g0 (docs/DESIGN.md eqs. (8)-(9)). Loads on interface nodes stay with part 1 (they enter f_I
  // below), so only f_N reaches the condensation.
  CondensedPart part = condense_non_operation_part(mesh_, elements_, partition_, loads(), fixed_);
  // K0 enters every hybrid matrix as one sparse block (k0_padded_, which set_young_modulus
  // rescales), so the dense K0 leaves the part. The rest of the part never changes: it is
  // shared with displacement snapshots, recovered on other threads, perhaps after this model
  // is gone.
  Eigen::MatrixXd k0 = std::move(part.K0);
  part.K0 = Eigen::MatrixXd();
  condensed_ = std::make_shared<const CondensedPart>(std::move(part));
  // Part 2's gravity never changes: kept, so a cut re-lumps the operation tets only.
  condensed_gravity_ = Vector::Zero(3 * mesh_.num_nodes());
  add_gravity_of(mesh_, partition_.condensed_tets, elements_.material().density, gravity_,
                 condensed_gravity_);
  timings_["condensation_assembly"] = condensed_->assembly_ms;
  timings_["condensation_factor"] = condensed_->factor_ms;
  timings_["condensation_solve"] = condensed_->solve_ms;
  timings_["condensation_products"] = condensed_->product_ms;

  u_ = Vector::Zero(3 * mesh_.num_nodes());
  const auto t0 = Clock::now();
  k0_padded_ = k0.sparseView(0.0, 0.0);
  k0 = Eigen::MatrixXd();
  rebuild_hybrid_system();
  refresh_factor();  // at precompute (a moved region's model: on the worker), not at a step
  timings_["hybrid_assembly"] = ms_since(t0);
  timings_["total"] = ms_since(start);
}

HybridModel::~HybridModel() = default;

Vector HybridModel::loads() const {
  return point_loads_ + gravity_loads(mesh_, elements_.material().density, gravity_);
}

void HybridModel::rebuild_hybrid_system(const std::vector<int>* changed,
                                        const std::vector<Triplet>* removed) {
  // Unknowns: free DOFs of I, then of O (operation nodes still used by a part-1 tet).
  std::vector<int> nodes = partition_.interface;
  nodes.insert(nodes.end(), partition_.operation.begin(), partition_.operation.end());
  const std::vector<int> old_rows = std::move(dofs_.global_of);
  dofs_ = make_dof_map(mesh_.num_nodes(), nodes, fixed_);
  const DofMap& idofs = condensed_->interface_dofs;
  interface_row_.resize(static_cast<size_t>(idofs.rows()));
  for (int k = 0; k < idofs.rows(); ++k)
    interface_row_[static_cast<size_t>(k)] = dofs_.row_of[static_cast<size_t>(idofs.global_of[k])];

  // K1 from part-1 tets, plus K0 on the interface block (eq. 17). The free interface DOFs are
  // the first rows, in the condensation's order (I is listed first and never changes), so
  // K0 enters as one sparse matrix kept from the condensation: a cut re-assembles part 1
  // only and adds K0 (a merge), never re-sorting the dense block's |3I|^2 triplets.
  for (int k = 0; k < idofs.rows(); ++k)
    if (interface_row_[static_cast<size_t>(k)] != k)
      throw std::logic_error("HybridModel: the interface DOFs are not the leading rows");
  if (!changed || !removed || !update_hybrid_matrix(old_rows, *changed, *removed)) {
    rows_changed_.reset();  // any row may have changed
    const SparseMatrix k1 = assemble_stiffness(mesh_, elements_, partition_.operation_tets, dofs_);
    merge_k0(k1, k0_padded_, a_);
    assembled_tets_ = mesh_.tets;
  }

  // Right-hand side: f_O, f_I - g0. The loads of the whole mesh, with part 2's gravity kept
  // from the start (a cut changes part-1 tets only).
  Vector f = point_loads_;
  f.head(condensed_gravity_.size()) += condensed_gravity_;
  add_gravity_of(mesh_, partition_.operation_tets, elements_.material().density, gravity_, f);
  b_ = gather(f, dofs_);
  for (int k = 0; k < idofs.rows(); ++k)
    b_[interface_row_[static_cast<size_t>(k)]] -= condensed_->g0[k];
  // Factored at first use (refresh_factor): a cut that frees pieces, or a ~cut slice of
  // several sweeps, changes the matrix or the held set more than once before the next solve.
  factor_stale_ = true;
  system_changed_ = true;
}

void HybridModel::refresh_factor() const {
  if (!factor_stale_) return;
  LinearSolver::History history;
  const std::vector<int>& now = dofs_.global_of;
  const auto common = std::mismatch(solver_dofs_.begin(), solver_dofs_.end(), now.begin(),
                                    now.begin() + std::min(now.size(), solver_dofs_.size()));
  history.kept_rows = static_cast<int>(common.first - solver_dofs_.begin());
  history.interface_rows = static_cast<int>(interface_row_.size());  // the leading rows
  if (rows_changed_) history.changed_rows = &*rows_changed_;
  std::vector<int> expected_rows;
  for (int node : expected_cut_nodes_)
    for (int c = 0; c < 3; ++c)
      if (node >= 0 && 3 * node + c < static_cast<int>(dofs_.row_of.size()))
        if (const int r = dofs_.row_of[static_cast<size_t>(3 * node + c)]; r >= 0)
          expected_rows.push_back(r);
  expected_cut_nodes_.clear();
  if (!expected_rows.empty()) history.expected_rows = &expected_rows;
  history.await_factor_ahead = settings_.await_factor_ahead;
  solver_->set_matrix(a_, held_dofs(), history);
  solver_dofs_ = now;
  rows_changed_.emplace();  // from here on, every change is listed (update_hybrid_matrix)
  factor_stale_ = false;
}

CgResult HybridModel::solve(const ImposedDisplacements& imposed) {
  // Same system, same imposed displacements: the last solution still solves it exactly, so
  // an idle step costs nothing (docs/DESIGN.md, per-step cost).
  if (!system_changed_ && imposed == last_imposed_) {
    last_.iterations = 0;
    return last_;
  }
  Vector x = gather(u_, dofs_);  // warm start: the last step's solution
  std::vector<std::uint8_t> constrained;
  if (!imposed.empty()) constrained.assign(static_cast<size_t>(dofs_.rows()), 0);
  for (const auto& [node, d] : imposed) {
    if (node < 0 || node >= mesh_.num_nodes())
      throw std::invalid_argument("HybridModel::solve: imposed node out of range");
    const NodeSet set = partition_.node_set[static_cast<size_t>(node)];
    if (set != NodeSet::kOperation && set != NodeSet::kInterface)
      throw std::invalid_argument(
          "HybridModel::solve: displacements can only be imposed on operation or interface "
          "nodes (the condensed part is fixed at precompute)");
    for (int c = 0; c < 3; ++c) {
      const int r = dofs_.row_of[static_cast<size_t>(3 * node + c)];
      if (r < 0) continue;  // fixed DOF stays zero
      x[r] = d[c];
      constrained[static_cast<size_t>(r)] = 1;
    }
  }
  if (dofs_.rows() > 0) {
    refresh_factor();
    last_ = solver_->solve(b_, x, constrained, settings_);
  } else {
    last_ = CgResult{};  // `none`: nothing to solve, u_S = c_S
    last_.converged = true;
  }
  scatter(x, dofs_, u_);
  // u_S and u_Q follow u_I alone: recovered on demand (displacement()), and only if u_I moved.
  Vector u_i = gather(u_, condensed_->interface_dofs);
  if (u_i != recovered_from_) condensed_stale_ = true;
  last_imposed_ = imposed;
  system_changed_ = false;
  return last_;
}

const Vector& HybridModel::displacement() const {
  if (!condensed_stale_) return u_;
  // u_N = K2_NN^-1 (f_N - K2_NI u_I) (docs/DESIGN.md eq. (13)) through the kept factor: S and Q at
  // once, exact to the factorization's rounding, no dense 3|S| x 3|I| operator in memory. The
  // same path as a snapshot recovered on another thread.
  DisplacementSnapshot s = displacement_snapshot();
  s.recover();
  ++recoveries_;
  adopt_recovery(s);
  return u_;
}

DisplacementSnapshot HybridModel::displacement_snapshot() const {
  DisplacementSnapshot s;
  s.u = u_;
  s.condensed = condensed_;
  s.stiffness_scale = condensed_scale_;
  s.stale = condensed_stale_;
  return s;
}

void HybridModel::adopt_recovery(const DisplacementSnapshot& s) const {
  // Only a recovery through this model's factor at its present stiffness; its u_I may be
  // older than the current one (then S and Q stay stale, as recovered from that u_I).
  if (s.stale || s.condensed != condensed_ || s.stiffness_scale != condensed_scale_) return;
  const DofMap& n = condensed_->condensed_dofs;
  if (n.rows() > 0) scatter(gather(s.u, n), n, u_);
  recovered_from_ = gather(s.u, condensed_->interface_dofs);
  condensed_stale_ = gather(u_, condensed_->interface_dofs) != recovered_from_;
}

void HybridModel::recover_interior() { displacement(); }

void HybridModel::set_displacement(const Vector& u) {
  if (u.size() != u_.size())
    throw std::invalid_argument("HybridModel::set_displacement: size does not match the mesh");
  u_ = u;
  system_changed_ = true;  // the next solve runs, warm from u
  condensed_stale_ = true;
}

void HybridModel::reset_displacement() {
  u_.setZero();
  system_changed_ = true;  // the next solve starts cold
  condensed_stale_ = true;
}

Vec3 HybridModel::reaction_force(const std::vector<int>& nodes) const {
  Vec3 sum = Vec3::Zero();
  for (int node : nodes) {
    if (node < 0 || node >= mesh_.num_nodes()) continue;
    for (int c = 0; c < 3; ++c) {
      const int r = dofs_.row_of[static_cast<size_t>(3 * node + c)];
      if (r < 0) continue;
      double ku = 0;
      for (SparseMatrix::InnerIterator it(a_, r); it; ++it)
        ku += it.value() * u_[dofs_.global_of[static_cast<size_t>(it.col())]];
      sum[c] += ku - b_[r];
    }
  }
  return sum;
}

bool HybridModel::update_hybrid_matrix(const std::vector<int>& old_rows,
                                       const std::vector<int>& changed,
                                       const std::vector<Triplet>& removed) {
  // Only when every DOF keeps its row (a cut appends its new nodes' DOFs): then the rows no
  // changed tet touches stay as they are, bit for bit (section 6.2 relies on it).
  const int n = dofs_.rows();
  if (a_.rows() != static_cast<Eigen::Index>(old_rows.size()) || n < a_.rows() ||
      !std::equal(old_rows.begin(), old_rows.end(), dofs_.global_of.begin()))
    return false;
  std::vector<Triplet> delta;
  delta.reserve(removed.size() + 144 * changed.size());
  for (const Triplet& t : removed) {
    const int r = dofs_.row_of[static_cast<size_t>(t.row())];
    const int c = dofs_.row_of[static_cast<size_t>(t.col())];
    if (r >= 0 && c >= 0) delta.emplace_back(r, c, t.value());
  }
  std::vector<int> operation_changed;
  for (int t : changed)
    if (partition_.operation_tet[static_cast<size_t>(t)]) operation_changed.push_back(t);
  add_element_triplets(mesh_, elements_, operation_changed, dofs_.row_of, dofs_.row_of, delta);
  std::vector<std::uint8_t> touched(static_cast<size_t>(n), 0);
  for (const Triplet& t : delta) touched[static_cast<size_t>(t.row())] = 1;
  if (rows_changed_)
    for (int r = 0; r < n; ++r)
      if (touched[static_cast<size_t>(r)] || r >= a_.rows()) rows_changed_->push_back(r);
  SparseMatrix d(n, n);
  d.setFromTriplets(delta.begin(), delta.end());
  // Couplings the cut removed are dropped, so a piece it severed is not held by a 1e-16 spring
  // (the singular-factor check of section 6 would not see it).
  add_difference(a_, d, touched, 1e-12, spare_);
  assembled_tets_.resize(mesh_.tets.size());
  for (int t : changed)
    assembled_tets_[static_cast<size_t>(t)] = mesh_.tets[static_cast<size_t>(t)];
  return true;
}

void HybridModel::update_operation_part(const std::vector<int>& changed_tets,
                                        const std::vector<NewNode>& new_nodes) {
  const int old_nodes = static_cast<int>(u_.size() / 3);
  const int n = mesh_.num_nodes();
  if (n - old_nodes != static_cast<int>(new_nodes.size()))
    throw std::invalid_argument(
        "HybridModel::update_operation_part: new_nodes does not match "
        "the nodes appended to the mesh");
  // New nodes: displacement interpolated from their parents (cut_result.hpp), unloaded.
  u_.conservativeResize(3 * n);
  point_loads_.conservativeResize(3 * n);
  fixed_.resize(static_cast<size_t>(n), 0);
  held_.resize(static_cast<size_t>(n), 0);
  for (int k = 0; k < static_cast<int>(new_nodes.size()); ++k) {
    const int node = old_nodes + k;
    const NewNode& nn = new_nodes[static_cast<size_t>(k)];
    const bool split = nn.kind == NewNode::Kind::kEdgeSplit;
    if (nn.kind == NewNode::Kind::kInTet) {  // docs/DESIGN.md eq. (21a)
      bool fixed = true;
      u_.segment<3>(3 * node).setZero();
      for (int i = 0; i < 4; ++i) {
        const int c = nn.corners[static_cast<size_t>(i)];
        if (c < 0 || c >= node)
          throw std::invalid_argument("HybridModel::update_operation_part: bad parent node");
        u_.segment<3>(3 * node) += nn.weights[static_cast<size_t>(i)] * u_.segment<3>(3 * c);
        fixed = fixed && fixed_[static_cast<size_t>(c)];
      }
      fixed_[static_cast<size_t>(node)] = fixed;
      point_loads_.segment<3>(3 * node).setZero();
      continue;
    }
    if (nn.a < 0 || nn.a >= node || (split && (nn.b < 0 || nn.b >= node)))
      throw std::invalid_argument("HybridModel::update_operation_part: bad parent node");
    if (split) {
      u_.segment<3>(3 * node) =
          (1 - nn.t) * u_.segment<3>(3 * nn.a) + nn.t * u_.segment<3>(3 * nn.b);
      fixed_[static_cast<size_t>(node)] =
          fixed_[static_cast<size_t>(nn.a)] && fixed_[static_cast<size_t>(nn.b)];
    } else {
      u_.segment<3>(3 * node) = u_.segment<3>(3 * nn.a);
      fixed_[static_cast<size_t>(node)] = fixed_[static_cast<size_t>(nn.a)];
      held_[static_cast<size_t>(node)] = held_[static_cast<size_t>(nn.a)];
    }
    point_loads_.segment<3>(3 * node).setZero();
  }
  // The changed tets' contributions as a_ holds them (their nodes then, their matrices now,
  // before the update), negated: the new matrix is a_ plus the difference.
  std::vector<Triplet> removed;
  for (int t : changed_tets) {
    if (t >= static_cast<int>(assembled_tets_.size()) ||
        !partition_.operation_tet[static_cast<size_t>(t)])
      continue;
    const Tet& e = assembled_tets_[static_cast<size_t>(t)];
    const Mat12& k = elements_[t];
    for (int a = 0; a < 12; ++a)
      for (int b = 0; b < 12; ++b)
        removed.emplace_back(3 * e[a / 3] + a % 3, 3 * e[b / 3] + b % 3, -k(a, b));
  }
  // Only the changed element matrices are recomputed.
  elements_.update(mesh_, changed_tets);
  // Only part 1 changed: the partition is updated from the part-1 tets alone. The condensed
  // part must be untouched: same I, S, Q and part-2 tets.
  if (!update_partition_for_operation_change(mesh_, changed_tets, partition_))
    throw std::logic_error(
        "HybridModel::update_operation_part: the change reached the "
        "condensed (non-operation) part");
  rebuild_hybrid_system(&changed_tets, &removed);
}

void HybridModel::set_young_modulus(double young_modulus) {
  if (!(young_modulus > 0)) throw std::invalid_argument("young_modulus must be > 0");
  const double s = young_modulus / elements_.material().young_modulus;
  elements_.set_young_modulus(young_modulus);
  k0_padded_ *= s;        // K0: K2 scales with E
  condensed_scale_ *= s;  // u_N recovery: K2_NN^-1 f_N scales with 1/E; g0 is a ratio
  condensed_stale_ = true;
  rebuild_hybrid_system();
}

std::vector<std::uint8_t> HybridModel::held_dofs() const {
  std::vector<std::uint8_t> rows;
  if (std::find(held_.begin(), held_.end(), 1) == held_.end()) return rows;  // none held
  rows.assign(static_cast<size_t>(dofs_.rows()), 0);
  for (int r = 0; r < dofs_.rows(); ++r) {
    const size_t node = static_cast<size_t>(dofs_.global_of[static_cast<size_t>(r)] / 3);
    rows[static_cast<size_t>(r)] = node < held_.size() && held_[node];
  }
  return rows;
}

void HybridModel::set_held_nodes(const std::vector<int>& nodes) {
  std::vector<std::uint8_t> held = held_flags(mesh_, nodes);
  if (held == held_) return;
  held_ = std::move(held);
  factor_stale_ = true;
  system_changed_ = true;
}

void HybridModel::set_solver(std::unique_ptr<LinearSolver> solver) {
  if (!solver) throw std::invalid_argument("HybridModel: no linear solver");
  solver_ = std::move(solver);
  factor_stale_ = true;
  refresh_factor();
  system_changed_ = true;
}

HybridModelCounts HybridModel::counts() const {
  HybridModelCounts c;
  c.nodes = mesh_.num_nodes();
  c.tets = mesh_.num_tets();
  c.dof_operation = dofs_.rows();
  c.nodes_operation = static_cast<int>(partition_.operation.size());
  c.nodes_interface = static_cast<int>(partition_.interface.size());
  c.nodes_surface_condensed = static_cast<int>(partition_.surface.size());
  c.nodes_interior_condensed = static_cast<int>(partition_.interior.size());
  return c;
}

}  // namespace stc
