#include "soft_tissue_cutting/condensation/condensed_part.hpp"

#include "soft_tissue_cutting/solve/schur_complement.hpp"

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

  // K0 = K2_II - K2_IN K2_NN^-1 K2_NI   (docs/DESIGN.md, condensation): one factorization of
  // the whole K^(2) with I last (solve/schur_complement.hpp) instead of 3|I| solves with
  // K2_NN's factor (the organ liver's 636 interface columns: 0.9 s of solves). First, so that
  // its factor is freed before K2_NN's is made (peak RSS at 200k tets: 1012 MB the other way round,
  // 804 MB so).
  t0 = clock::now();
  c.K0 = schur_complement(k_nn, c.K2_NI, k_ii);
  c.solve_ms = ms_since(t0);
  t0 = clock::now();
  // Kept for the recovery of u_S and u_Q (recovery/).
  auto factor = std::make_shared<SparseCholesky>(k_nn);
  c.factor_ms = ms_since(t0);
  // g0 = K2_IN K2_NN^-1 f_N: one solve.
  t0 = clock::now();
  c.g0 = c.K2_NI.transpose() * factor->solve(c.f_N);
  c.K0 = 0.5 * (c.K0 + c.K0.transpose()).eval();  // symmetric to rounding
  c.factor_NN = std::move(factor);
  c.product_ms = ms_since(t0);
  return c;
}

}  // namespace stc
