// A sparse Cholesky factor of the hybrid matrix whose trailing block, the frame around the
// last cut, is refactored alone when a cut changes nothing outside it (docs/DESIGN.md section 6,
// "A cut refactors its frame").
//
// A cut changes the stiffness of a few tets near the blade and appends the DOFs of the nodes it
// creates; every other row of the hybrid matrix, the dense interface block K0 above all, stays
// as it was. With the frame's DOFs B ordered after all the others F, A = L L^T has
//   L = [L_FF 0; L_BF L_BB],   L_BB L_BB^T = A_BB - W,   W = A_BF A_FF^-1 A_FB,
// and L_FF, L_BF and W depend on A_FF and A_FB only. A matrix that differs from the factored one
// in its frame rows alone (new DOFs join the frame; they couple to frame DOFs only) is factored
// by the dense Cholesky of its frame's Schur complement S' = A'_BB - W, eq. (26): the organ
// liver's 2,500-DOF factor with its 636-DOF dense interface block costs ~9 ms, a frame of a few
// hundred DOFs well under one. Solves use the kept sparse factor for the F part, eq. (27):
//   z = L^-1 P b,  r_B = L_BB z_B (= b_B - L_BF z_F),  x_B = S'^-1 r_B,
//   x = P^T L^-T [z_F; L_BB^T x_B]
// (the last solve's trailing block returns x_B itself; only its F rows are new), exact to the
// rounding of a direct solve. A later change that reaches a few rows X of F (the blade's next
// cut one ring past the frame) moves them into the frame without a refactorization: the
// Schur complement of A_F'F' (F' = F \ X) onto X u B follows from L's solves with X's unit
// columns, eq. (28), and a solve takes X's rows out of its one backward substitution, eq. (29).
#pragma once

#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <Eigen/Core>

#include <limits>
#include <memory>
#include <vector>

namespace stc {

class FramedCholesky final : public CholeskySolve {
 public:
  // At most this many changed rows outside the frame join it (eq. (28)) before a change
  // refactors the whole matrix: each costs three column solves with the sparse factor when it
  // joins, and every later solve a few products of its size. The organ liver's follow stroke
  // left its frame by 3-24 rows at most of the cuts that refactored.
  static constexpr int kMaxExtraRows = 48;

  // Factors `a` (SPD, both triangles stored) with the DOFs in `frame` eliminated last and the
  // others in AMD order (the factor keeps the matrix: a moved one is not copied again). Throws
  // std::runtime_error if it is not positive definite.
  FramedCholesky(SparseMatrix a, std::vector<int> frame);
  ~FramedCholesky() override;
  FramedCholesky(const FramedCholesky&) = delete;
  FramedCholesky& operator=(const FramedCholesky&) = delete;

  // Takes `a` by refactoring the frame alone if it can: `a`'s leading rows() rows are the same
  // DOFs as the factored matrix's, at most kMaxExtraRows rows outside the frame changed since
  // the factorization (pattern or values: they join the frame as extra rows, eq. (28)), and the
  // frame's Schur complement is positive definite. Rows beyond rows() are new DOFs and join the
  // frame. Returns false, leaving this factor as it was, otherwise.
  // `changed`, when given, lists every row in which `a` may differ from the factored matrix
  // (the others are taken as equal, not compared). A frame that would grow past `max_frame`
  // rows is refused before any work on it (the caller refactors instead).
  bool update(const SparseMatrix& a, const std::vector<int>* changed = nullptr,
              int max_frame = std::numeric_limits<int>::max());

  Vector solve(const Vector& b) const override;
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const override;
  int rows() const override { return rows_; }
  int frame_size() const { return static_cast<int>(frame_.size()); }
  int updates() const { return updates_; }
  // Rows of the sparse part that later changes moved into the frame (eq. (28); at most
  // kMaxExtraRows).
  int extra_rows() const;
  // Floating-point operations of the sparse factorization this object made (CHOLMOD's count
  // from the analysis): what refactoring a matrix like it costs.
  double factor_flops() const { return factor_flops_; }

  // The rows where `a` differs from `previous` (same leading rows; rows beyond previous.rows()
  // count as changed), grown by `rings` rings of neighbours in `a`'s graph: the frame to factor
  // `a` with so that the next cuts nearby fall inside it. The first `dense` rows (the interface
  // block, where each row neighbours all the others) join it but never grow it.
  static std::vector<int> frame_around_changes(const SparseMatrix& previous, const SparseMatrix& a,
                                               int dense, int rings);
  // The same around rows known to have changed.
  static std::vector<int> frame_around(const SparseMatrix& a, const std::vector<int>& changed,
                                       int dense, int rings);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<int> frame_;  // frame DOFs in their elimination order, new DOFs last
  int rows_ = 0;
  int updates_ = 0;
  double factor_flops_ = 0;
};

}  // namespace stc
