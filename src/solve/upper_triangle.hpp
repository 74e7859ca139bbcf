// The upper triangle of a symmetric matrix stored with both triangles (row-major), as the
// column-major matrix CHOLMOD is shown (stype = 1).
#pragma once

#include "soft_tissue_cutting/solve/linear_solver.hpp"  // SparseMatrix

namespace stc {

// A is symmetric, so its row-major arrays are also its column-major arrays: row r's entries
// with column <= r are column r of the upper triangle, copied as they are, not transposed.
// CHOLMOD analyses and factors the upper triangle: a lower one would be transposed on every
// factorization (7 % of the thigh's cutting step), and it scans every stored entry, so only
// that triangle is passed.
Eigen::SparseMatrix<double, Eigen::ColMajor, int> upper_triangle(const SparseMatrix& a);

}  // namespace stc
