#include "soft_tissue_cutting/simulation/hybrid_model.hpp"

#include "soft_tissue_cutting/assembly/loads.hpp"

#include <chrono>
#include <stdexcept>

namespace stc {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

}  // namespace

HybridModel::HybridModel(const Scene& scene, std::unique_ptr<LinearSolver> solver)
    : mesh_(scene.mesh),
      gravity_(scene.gravity),
      point_loads_(point_loads(scene)),
      fixed_(fixed_node_mask(scene)),
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

  // K0, g0 (METHOD 3). Loads on interface nodes stay with part 1 (they enter f_I below), so
  // only f_N reaches the condensation.
  condensed_ = condense_non_operation_part(mesh_, elements_, partition_, loads(), fixed_);
  timings_["condensation_assembly"] = condensed_.assembly_ms;
  timings_["condensation_factor"] = condensed_.factor_ms;
  timings_["condensation_solve"] = condensed_.solve_ms;
  timings_["condensation_products"] = condensed_.product_ms;

  t0 = Clock::now();
  recovery_ = make_surface_recovery(condensed_, mesh_.num_nodes(), partition_.surface, fixed_);
  timings_["recovery_operator"] = ms_since(t0);

  u_ = Vector::Zero(3 * mesh_.num_nodes());
  t0 = Clock::now();
  rebuild_hybrid_system();
  timings_["hybrid_assembly"] = ms_since(t0);
  timings_["total"] = ms_since(start);
}

HybridModel::~HybridModel() = default;

Vector HybridModel::loads() const {
  return point_loads_ + gravity_loads(mesh_, elements_.material().density, gravity_);
}

void HybridModel::rebuild_hybrid_system() {
  // Unknowns: free DOFs of I, then of O (operation nodes still used by a part-1 tet).
  std::vector<int> nodes = partition_.interface;
  nodes.insert(nodes.end(), partition_.operation.begin(), partition_.operation.end());
  dofs_ = make_dof_map(mesh_.num_nodes(), nodes, fixed_);
  const DofMap& idofs = condensed_.interface_dofs;
  interface_row_.resize(static_cast<size_t>(idofs.rows()));
  for (int k = 0; k < idofs.rows(); ++k)
    interface_row_[static_cast<size_t>(k)] = dofs_.row_of[static_cast<size_t>(idofs.global_of[k])];

  // K1 from part-1 tets, plus K0 on the interface block (eq. 17).
  std::vector<Triplet> t;
  t.reserve(partition_.operation_tets.size() * 144 +
            static_cast<size_t>(condensed_.K0.size()));
  add_element_triplets(mesh_, elements_, partition_.operation_tets, dofs_.row_of, dofs_.row_of, t);
  for (int j = 0; j < idofs.rows(); ++j)
    for (int i = 0; i < idofs.rows(); ++i)
      t.emplace_back(interface_row_[static_cast<size_t>(i)], interface_row_[static_cast<size_t>(j)],
                     condensed_.K0(i, j));
  a_ = SparseMatrix(dofs_.rows(), dofs_.rows());
  a_.setFromTriplets(t.begin(), t.end());

  // Right-hand side: f_O, f_I - g0.
  b_ = gather(loads(), dofs_);
  for (int k = 0; k < idofs.rows(); ++k) b_[interface_row_[static_cast<size_t>(k)]] -= condensed_.g0[k];
  solver_->set_matrix(a_);
}

CgResult HybridModel::solve(const ImposedDisplacements& imposed) {
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
    last_ = solver_->solve(b_, x, constrained, settings_);
  } else {
    last_ = CgResult{};  // `none`: nothing to solve, u_S = c_S
    last_.converged = true;
  }
  scatter(x, dofs_, u_);
  recover_surface();
  return last_;
}

void HybridModel::recover_surface() {
  // u_S = c_S + R u_I (METHOD 4).
  const Vector u_i = gather(u_, condensed_.interface_dofs);
  scatter(recovery_.recover(u_i), recovery_.surface_dofs, u_);
}

void HybridModel::recover_interior() {
  if (condensed_.condensed_dofs.rows() == 0) return;
  const Vector u_i = gather(u_, condensed_.interface_dofs);
  scatter(recover_condensed(condensed_, u_i, condensed_scale_), condensed_.condensed_dofs, u_);
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

void HybridModel::update_operation_part(const std::vector<int>& changed_tets,
                                        const std::vector<NewNode>& new_nodes) {
  const int old_nodes = static_cast<int>(u_.size() / 3);
  const int n = mesh_.num_nodes();
  if (n - old_nodes != static_cast<int>(new_nodes.size()))
    throw std::invalid_argument("HybridModel::update_operation_part: new_nodes does not match "
                                "the nodes appended to the mesh");
  // New nodes: displacement interpolated from their parents (cut_result.hpp), unloaded.
  u_.conservativeResize(3 * n);
  point_loads_.conservativeResize(3 * n);
  fixed_.resize(static_cast<size_t>(n), 0);
  for (int k = 0; k < static_cast<int>(new_nodes.size()); ++k) {
    const int node = old_nodes + k;
    const NewNode& nn = new_nodes[static_cast<size_t>(k)];
    const bool split = nn.kind == NewNode::Kind::kEdgeSplit;
    if (nn.a < 0 || nn.a >= node || (split && (nn.b < 0 || nn.b >= node)))
      throw std::invalid_argument("HybridModel::update_operation_part: bad parent node");
    if (split) {
      u_.segment<3>(3 * node) = (1 - nn.t) * u_.segment<3>(3 * nn.a) + nn.t * u_.segment<3>(3 * nn.b);
      fixed_[static_cast<size_t>(node)] = fixed_[static_cast<size_t>(nn.a)] && fixed_[static_cast<size_t>(nn.b)];
    } else {
      u_.segment<3>(3 * node) = u_.segment<3>(3 * nn.a);
      fixed_[static_cast<size_t>(node)] = fixed_[static_cast<size_t>(nn.a)];
    }
    point_loads_.segment<3>(3 * node).setZero();
  }
  // Only the changed element matrices are recomputed.
  elements_.update(mesh_, changed_tets);
  std::vector<std::uint8_t> operation_tet = partition_.operation_tet;
  operation_tet.resize(static_cast<size_t>(mesh_.num_tets()), 1);
  for (int t : changed_tets) operation_tet[static_cast<size_t>(t)] = 1;
  Partition p = partition_from_labels(mesh_, std::move(operation_tet));
  // The condensed part must be untouched: same I, S, Q and part-2 tets.
  if (p.interface != partition_.interface || p.surface != partition_.surface ||
      p.interior != partition_.interior || p.condensed_tets != partition_.condensed_tets)
    throw std::logic_error("HybridModel::update_operation_part: the change reached the "
                           "condensed (non-operation) part");
  partition_ = std::move(p);
  rebuild_hybrid_system();
}

void HybridModel::set_young_modulus(double young_modulus) {
  if (!(young_modulus > 0)) throw std::invalid_argument("young_modulus must be > 0");
  const double s = young_modulus / elements_.material().young_modulus;
  elements_.set_young_modulus(young_modulus);
  condensed_.K0 *= s;        // K2 scales with E
  recovery_.c_S /= s;        // [K2_NN^-1 f_N]_S scales with 1/E; R and g0 are ratios
  condensed_scale_ *= s;
  rebuild_hybrid_system();
}

void HybridModel::set_solver(std::unique_ptr<LinearSolver> solver) {
  if (!solver) throw std::invalid_argument("HybridModel: no linear solver");
  solver_ = std::move(solver);
  solver_->set_matrix(a_);
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
