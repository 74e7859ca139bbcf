// Sparse Cholesky factorization of an SPD matrix through CHOLMOD's supernodal LL^T
// (SuiteSparse). Used once per session for K2_NN of the condensed part (docs/DESIGN.md section 4)
// and by the reference direct solver of the full model. The CHOLMOD headers stay inside one
// translation unit (pimpl).
#pragma once

#include "soft_tissue_cutting/solve/linear_solver.hpp"  // SparseMatrix, Vector

#include <Eigen/Core>

#include <memory>

namespace stc {

// kSupernodal: dense BLAS supernodes, for large factors (K2_NN of the condensation).
// kSimplicial: up-looking LL^T without BLAS: ~20% faster on the thigh's ~800-DOF hybrid
// matrix (K0 makes a dense 345-DOF tail) with the reference BLAS; with OpenBLAS, which
// ./tissue setup installs, supernodal is faster (7.0 vs 10.6 ms), so the CG preconditioner
// uses supernodal too.
enum class CholeskyMethod { kSupernodal, kSimplicial };

// Fill-reducing ordering. kDefault: CHOLMOD's choice (AMD, then METIS when AMD's fill is
// high). kAmd: AMD alone. On the hybrid matrix (a dense interface block over a small sparse
// operation part) METIS was chosen and filled no less than AMD (organ liver: 389k vs 362k
// factor entries) while the analysis took 2-3x longer (18 vs 8 ms), and every cut re-analyses.
enum class CholeskyOrdering { kDefault, kAmd };

// What the capacitance solve (held_dof_solve.hpp) and the preconditioned CG need of a factor.
class CholeskySolve {
 public:
  virtual ~CholeskySolve() = default;
  // X = A^-1 B for all columns of B at once.
  virtual Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const = 0;
  virtual Vector solve(const Vector& b) const = 0;
  virtual int rows() const = 0;
};

class SparseCholesky final : public CholeskySolve {
 public:
  SparseCholesky();
  ~SparseCholesky() override;
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  // Throws std::runtime_error if the matrix is not positive definite (e.g. a piece of the
  // mesh with no fixed node and no interface to hold it).
  explicit SparseCholesky(const SparseMatrix& a,
                          CholeskyMethod method = CholeskyMethod::kSupernodal,
                          CholeskyOrdering ordering = CholeskyOrdering::kDefault);

  // Where a factorization of `a` meets a pivot that is not positive: the row/column of `a` at
  // which a simplicial LL^T (AMD order) stops, so a mode of `a` that nothing holds involves it;
  // -1 if `a` is positive definite. A diagnosis for failures (it factors `a` once more).
  static int first_failing_column(const SparseMatrix& a);

  // X = A^-1 B for all columns of B in one CHOLMOD call. Thread-safe: the factor is never
  // changed after construction and each call has its own CHOLMOD workspace, so threads may
  // share one factor (the condensed part's, recovered on the ROS display thread).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const override;
  Vector solve(const Vector& b) const override;
  int rows() const override { return rows_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int rows_ = 0;
};

// The reference direct solve of the general (uncondensed) model, for tests:
// K_ff u_f = f_f - K_fc u_c where constrained DOFs (constrained[i] != 0) take their value from
// x on entry; the result overwrites x.
void solve_direct(const SparseMatrix& a, const Vector& b, Vector& x,
                  const std::vector<std::uint8_t>& constrained = {});

}  // namespace stc
