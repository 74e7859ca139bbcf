// The non-operation part (part 2) condensed onto the interface (docs/DESIGN.md section 4):
//   K0 = K2_II - K2_IN K2_NN^-1 K2_NI   (dense, over the free interface DOFs)
//   g0 = K2_IN K2_NN^-1 f_N
// computed once per session from one CHOLMOD supernodal factorization of K2_NN and
// multi-right-hand-side solves X = K2_NN^-1 [K2_NI | f_N] in column blocks (only K2_IN X is
// kept). The factor, K2_NI and f_N are kept for the recovery of u_S and u_Q (recovery/).
#pragma once

#include "soft_tissue_cutting/assembly/global_assembly.hpp"
#include "soft_tissue_cutting/partition/partition.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <Eigen/Core>

#include <memory>

namespace stc {

struct CondensedPart {
  DofMap interface_dofs;  // free DOFs of I (rows of K0, g0)
  DofMap condensed_dofs;  // free DOFs of N = S u Q (rows of K2_NN)
  Eigen::MatrixXd K0;     // 3|I|_free square, symmetric
  Vector g0;
  // Kept for the recovery u_N = K2_NN^-1 (f_N - K2_NI u_I).
  SparseMatrix K2_NI;
  Vector f_N;
  std::shared_ptr<const SparseCholesky> factor_NN;  // K2_NN = L L^T

  // Milliseconds spent: assembly of part 2, factorization, multi-RHS solves, K0/g0 products.
  double assembly_ms = 0, factor_ms = 0, solve_ms = 0, product_ms = 0;
};

// loads: global 3n vector (point loads + gravity of every tet). Fixed nodes are eliminated.
// Throws std::runtime_error if K2_NN is singular (a piece of part 2 neither fixed nor attached
// to the interface).
CondensedPart condense_non_operation_part(const TetMesh& mesh,
                                          const ElementStiffnessCache& elements,
                                          const Partition& partition, const Vector& loads,
                                          const std::vector<std::uint8_t>& fixed_node);

}  // namespace stc
