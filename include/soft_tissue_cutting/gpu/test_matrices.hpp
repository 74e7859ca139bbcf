// Synthetic SPD matrices shaped like the hybrid system of docs/DESIGN.md section 4, for the GPU
// tests and bench/bench_gpu.cpp (the paper's Table 2, section 7): a sparse 3D-elasticity-like
// part (3 DOF per node, 7-point node stencil, 3x3 blocks: kron(Poisson, B) with B SPD) plus a
// dense "interface" block (the condensed K0 couples all interface DOFs).
#pragma once

#include "soft_tissue_cutting/solve/linear_solver.hpp"

namespace stc {
namespace gpu {

// 3 * nodes DOF; nodes laid out in an nx x ny x (as needed) box, first `nodes` nodes kept.
SparseMatrix elasticity_like(int nodes, int nx, int ny);
// a + a dense symmetric block over DOFs [0, d) made diagonally dominant (stays SPD).
SparseMatrix with_dense_block(const SparseMatrix& a, int d, unsigned seed);
// Longest row, off-diagonal non-zeros.
int max_offdiag_row(const SparseMatrix& a);
// Table 2 stand-in: `dof` DOF (multiple of 3) whose longest row has exactly `max_row`
// off-diagonal non-zeros, reached by the dense interface block (plus a few padding links).
SparseMatrix table2_matrix(int dof, int max_row, unsigned seed = 1);
// Uniform in [-1, 1], reproducible from `seed` (right-hand sides and SpMV inputs).
Vector random_vector(Eigen::Index n, unsigned seed);

}  // namespace gpu
}  // namespace stc
