// The exact solve of the hybrid system (docs/DESIGN.md eq. (10)) with some DOFs held
// (contact, held pieces: eq. (14)) through a factor of the whole matrix and a small
// capacitance system on the held DOFs (docs/DESIGN.md eqs. (24)-(25)):
//   y = A^-1 b,   W = A^-1 E_c,   (E_c^T W) mu = x_c - y_c,   x = y + W mu.
// y and the columns of W are kept until the matrix changes (reset()), so a pressing step
// that holds the same nodes as the last one costs a k x k solve and one n x k product; a
// newly held DOF costs one column of a multi-right-hand-side solve. The caller checks the
// residual: with a shifted factor (held free piece) the answer is only a good start.
#pragma once

#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <Eigen/Core>

#include <unordered_map>
#include <vector>

namespace stc {

class HeldDofSolve {
 public:
  // The matrix changed: every kept y and W column is stale.
  void reset();
  // x on entry: held DOFs (held[i] rows) carry their prescribed values; on return every other
  // row holds the solution of A_ff x_f = b_f - A_fc x_c through `factor` (A = L L^T).
  void solve(const CholeskySolve& factor, const Vector& b, const std::vector<int>& held, Vector& x);
  // Columns of W currently kept (for tests).
  int kept_columns() const { return static_cast<int>(column_of_.size()); }

 private:
  Vector b_, y_;  // y = A^-1 b for the last b
  bool have_y_ = false;
  std::unordered_map<int, int> column_of_;  // held DOF -> its column of w_
  Eigen::MatrixXd w_;                       // n x kept: A^-1 e_c
};

}  // namespace stc
