#include "soft_tissue_cutting/condensation/condensed_part.hpp"

#include <chrono>

namespace stc {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::vector<int> concat(const std::vector<int>& a, const std::vector<int>& b) {
  std::vector<int> out(a);
  out.insert(out.end(), b.begin(), b.end());
  return out;
}

}  // namespace

CondensedPart condense_non_operation_part(const TetMesh& mesh,
                                          const ElementStiffnessCache& elements,
                                          const Partition& partition, const Vector& loads,
                                          const std::vector<std::uint8_t>& fixed_node) {
  using clock = std::chrono::steady_clock;
  CondensedPart c;
  auto t0 = clock::now();
  const int n = mesh.num_nodes();
  c.interface_dofs = make_dof_map(n, partition.interface, fixed_node);
  // N ordered S first, then Q: the surface rows of X are then one contiguous block.
  c.condensed_dofs = make_dof_map(n, concat(partition.surface, partition.interior), fixed_node);
  const auto& part2 = partition.condensed_tets;
  // K^(2) blocks from part-2 tets only (docs/DESIGN.md section 3).
  const SparseMatrix k_ii = assemble_block(mesh, elements, part2, c.interface_dofs, c.interface_dofs);
  const SparseMatrix k_nn = assemble_block(mesh, elements, part2, c.condensed_dofs, c.condensed_dofs);
  c.K2_NI = assemble_block(mesh, elements, part2, c.condensed_dofs, c.interface_dofs);
  c.f_N = gather(loads, c.condensed_dofs);
  c.assembly_ms = ms_since(t0);

  t0 = clock::now();
  auto factor = std::make_shared<SparseCholesky>(k_nn);
  c.factor_ms = ms_since(t0);

  // One CHOLMOD solve for all right-hand sides [K2_NI | f_N].
  t0 = clock::now();
  const int ni = c.interface_dofs.rows(), nn = c.condensed_dofs.rows();
  Eigen::MatrixXd rhs(nn, ni + 1);
  rhs.leftCols(ni) = Eigen::MatrixXd(c.K2_NI);
  rhs.col(ni) = c.f_N;
  Eigen::MatrixXd x = factor->solve(rhs);
  c.solve_ms = ms_since(t0);

  t0 = clock::now();
  c.solution_operator = x.leftCols(ni);
  c.load_response = x.col(ni);
  const SparseMatrix k_in = c.K2_NI.transpose();
  // K0 = K2_II - K2_IN X,  g0 = K2_IN K2_NN^-1 f_N   (docs/DESIGN.md eqs. (8)-(9))
  c.K0 = Eigen::MatrixXd(k_ii);
  c.K0.noalias() -= k_in * c.solution_operator;
  c.K0 = 0.5 * (c.K0 + c.K0.transpose()).eval();  // symmetric to rounding
  c.g0 = k_in * c.load_response;
  c.factor_NN = std::move(factor);
  c.product_ms = ms_since(t0);
  return c;
}

}  // namespace stc
