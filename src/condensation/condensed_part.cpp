#include "soft_tissue_cutting/condensation/condensed_part.hpp"

#include <algorithm>
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

// Columns of X = K2_NN^-1 [K2_NI | f_N] solved at once: enough for CHOLMOD's dense BLAS
// kernels, small enough that the block (rows x columns doubles) stays near 32 MB at any size.
int block_columns(int rows) {
  return std::clamp(static_cast<int>((32l << 20) / 8 / std::max(rows, 1)), 16, 256);
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
  // N ordered S first, then Q: the surface DOFs are then the head of u_N.
  c.condensed_dofs = make_dof_map(n, concat(partition.surface, partition.interior), fixed_node);
  const auto& part2 = partition.condensed_tets;
  // K^(2) blocks from part-2 tets only (docs/DESIGN.md section 3).
  const SparseMatrix k_ii =
      assemble_block(mesh, elements, part2, c.interface_dofs, c.interface_dofs);
  const SparseMatrix k_nn =
      assemble_block(mesh, elements, part2, c.condensed_dofs, c.condensed_dofs);
  c.K2_NI = assemble_block(mesh, elements, part2, c.condensed_dofs, c.interface_dofs);
  c.f_N = gather(loads, c.condensed_dofs);
  c.assembly_ms = ms_since(t0);

  t0 = clock::now();
  auto factor = std::make_shared<SparseCholesky>(k_nn);
  c.factor_ms = ms_since(t0);

  // K0 = K2_II - K2_IN K2_NN^-1 K2_NI,  g0 = K2_IN K2_NN^-1 f_N   (docs/DESIGN.md, condensation)
  // X = K2_NN^-1 [K2_NI | f_N] is solved block by block and only K2_IN X is kept: X itself
  // is 3|N| x 3|I| dense (gigabytes at organ scale) and nothing else needs it (u_S and u_Q
  // are recovered through the factor, recovery/).
  const int ni = c.interface_dofs.rows(), nn = c.condensed_dofs.rows();
  const Eigen::SparseMatrix<double, Eigen::ColMajor, int> k_ni(c.K2_NI);
  const SparseMatrix k_in = c.K2_NI.transpose();
  c.K0 = Eigen::MatrixXd(k_ii);
  c.g0 = Vector::Zero(ni);
  const int width = block_columns(nn);
  Eigen::MatrixXd rhs;
  for (int j0 = 0; j0 <= ni; j0 += width) {  // column ni is f_N
    const int w = std::min(width, ni + 1 - j0);
    auto ts = clock::now();
    rhs.setZero(nn, w);
    const int wk = std::min(w, ni - j0);  // K2_NI columns in this block
    if (wk > 0) rhs.leftCols(wk) = k_ni.middleCols(j0, wk);
    if (wk < w) rhs.col(wk) = c.f_N;
    const Eigen::MatrixXd x = factor->solve(rhs);
    c.solve_ms += ms_since(ts);
    ts = clock::now();
    const Eigen::MatrixXd kx = k_in * x;
    if (wk > 0) c.K0.middleCols(j0, wk) -= kx.leftCols(wk);
    if (wk < w) c.g0 = kx.col(wk);
    c.product_ms += ms_since(ts);
  }
  t0 = clock::now();
  c.K0 = 0.5 * (c.K0 + c.K0.transpose()).eval();  // symmetric to rounding
  c.factor_NN = std::move(factor);
  c.product_ms += ms_since(t0);
  return c;
}

}  // namespace stc
