// The Schur complement of a sparse SPD block, by one partial sparse Cholesky factorization
// (CHOLMOD, supernodal): the condensation's K0 = K2_II - K2_IN K2_NN^-1 K2_NI (docs/DESIGN.md
// section 4, eq. (6)) without a solve per interface column.
#pragma once

#include "soft_tissue_cutting/solve/linear_solver.hpp"  // SparseMatrix

#include <Eigen/Core>

namespace stc {

// S = A_BB - A_BA A_AA^-1 A_AB for the SPD matrix [A_AA A_AB; A_AB^T A_BB] (the blocks as
// given: a_aa square, a_ab with a_aa's rows and a_bb's columns, a_bb square; each symmetric
// block may be given whole or as its upper triangle's transpose, only its upper triangle is
// read). The whole matrix is factored once as L L^T with B ordered last (A by CAMD with that
// constraint): the trailing block of L is then chol(S), so S = L_BB L_BB^T - the elimination
// of A does the work that 3|B| solves with A_AA's factor would, in BLAS-3 supernodes.
// Throws std::runtime_error if the matrix is not positive definite.
Eigen::MatrixXd schur_complement(const SparseMatrix& a_aa, const SparseMatrix& a_ab,
                                 const SparseMatrix& a_bb);

}  // namespace stc
