// The elimination order of a hybrid matrix with its dense interface rows last, and the pattern
// its symbolic factorization is computed from (docs/DESIGN.md section 6.2, "Ordering").
//
// The condensed block K0 couples most interface DOFs with all the others: on the organ liver
// its dense rows hold ~80 % of the matrix's entries, and ordering (CAMD) and analysing
// (CHOLMOD's symbolic factorization) the whole matrix read every one of them at each
// refactorization (~4 of ~12 ms). Neither needs them. AMD itself sets rows denser than
// 10 sqrt(n) aside and orders them last; here they are found by their counts and set aside
// before the graph is built. And once the first of them is eliminated, its row of a "star"
// (that row joined to every other dense row) fills their whole block in the factor, so the
// analysis reads the star instead of the block.
#pragma once

#include "soft_tissue_cutting/solve/linear_solver.hpp"  // SparseMatrix

#include <cholmod.h>

#include <vector>

namespace stc {

using ColMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// The rows of `a` (both triangles stored) with more entries than AMD's dense threshold,
// max(16, 10 sqrt(n)) (CAMD's default): 1 for those, 0 for the others.
std::vector<char> dense_rows(const SparseMatrix& a);

// The elimination order of the matrix whose upper triangle is `upper` (column-major): every
// row with in_frame[r] == 0 before every frame row; within each set, the sparse rows in the
// order of CHOLMOD's constrained AMD of their own graph (the dense rows left out), then the
// set's dense rows in index order. Throws std::runtime_error if CAMD fails.
std::vector<int> order_dense_last(const ColMatrix& upper, const std::vector<char>& dense,
                                  const std::vector<char>& in_frame, cholmod_common& common);

// `upper`'s pattern with the entries between two dense rows replaced by a star: the dense
// rows' diagonal, and `hub` (the dense row eliminated first) joined to every other dense row.
// Factored in an order that eliminates every dense row after `hub`, its symbolic factor
// contains `upper`'s pattern (the hub's elimination fills the dense rows' whole block): the
// pattern to analyse, while the numerical factorization takes `upper` itself. Columns sorted.
ColMatrix dense_star_pattern(const ColMatrix& upper, const std::vector<char>& dense, int hub);

}  // namespace stc
