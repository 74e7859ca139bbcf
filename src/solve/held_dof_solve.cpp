// Capacitance solve on the held DOFs (docs/DESIGN.md eqs. (24)-(25)): the Lagrange form of
// eq. (14), A x = b + E_c mu with E_c^T x = x_c, whose multipliers mu (the forces that hold
// the DOFs) solve the k x k system G mu = x_c - y_c with G = E_c^T A^-1 E_c = (A^-1)_cc, SPD.
#include "soft_tissue_cutting/solve/held_dof_solve.hpp"

#include <Eigen/Cholesky>

namespace stc {
namespace {

// Kept columns of W at most: beyond that the cache is dropped and rebuilt from the DOFs of
// the current step (a long press slides over many nodes; memory stays n x kMaxColumns).
constexpr int kMaxColumns = 192;

}  // namespace

void HeldDofSolve::reset() {
  have_y_ = false;
  column_of_.clear();
  w_.resize(0, 0);
}

void HeldDofSolve::solve(const CholeskySolve& factor, const Vector& b, const std::vector<int>& held,
                         Vector& x) {
  const Eigen::Index n = b.size();
  if (!have_y_ || b_.size() != n || b_ != b) {
    y_ = factor.solve(b);
    b_ = b;
    have_y_ = true;
  }
  std::vector<int> missing;
  for (int c : held)
    if (!column_of_.count(c)) missing.push_back(c);
  if (!missing.empty()) {
    if (column_of_.size() + missing.size() > static_cast<size_t>(kMaxColumns)) {
      column_of_.clear();
      w_.resize(0, 0);
      missing = held;
    }
    Eigen::MatrixXd e = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(missing.size()));
    for (size_t j = 0; j < missing.size(); ++j) e(missing[j], static_cast<Eigen::Index>(j)) = 1;
    const Eigen::MatrixXd w_new = factor.solve(e);  // one multi-right-hand-side solve
    const Eigen::Index kept = static_cast<Eigen::Index>(column_of_.size());
    if (w_.rows() != n) w_.resize(n, 0);
    w_.conservativeResize(n, kept + w_new.cols());
    w_.rightCols(w_new.cols()) = w_new;
    for (size_t j = 0; j < missing.size(); ++j)
      column_of_[missing[j]] = static_cast<int>(kept + static_cast<Eigen::Index>(j));
  }
  const Eigen::Index k = static_cast<Eigen::Index>(held.size());
  std::vector<int> col(held.size());
  for (size_t i = 0; i < held.size(); ++i) col[i] = column_of_.at(held[i]);
  // G = (A^-1)_cc and the prescribed values' misfit x_c - y_c (eq. (24)).
  Eigen::MatrixXd g(k, k);
  Vector misfit(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    misfit[i] = x[held[static_cast<size_t>(i)]] - y_[held[static_cast<size_t>(i)]];
    for (Eigen::Index j = 0; j < k; ++j)
      g(i, j) = w_(held[static_cast<size_t>(i)], col[static_cast<size_t>(j)]);
  }
  Vector mu;
  if (k > 0) {
    g = 0.5 * (g + g.transpose()).eval();  // symmetric to rounding
    Eigen::LDLT<Eigen::MatrixXd> ldlt(g);
    mu = ldlt.solve(misfit);
  }
  // x = y + W mu (eq. (25)); the held rows keep their prescribed values exactly.
  Vector held_values(k);
  for (Eigen::Index i = 0; i < k; ++i) held_values[i] = x[held[static_cast<size_t>(i)]];
  x = y_;
  for (Eigen::Index j = 0; j < k; ++j) x.noalias() += mu[j] * w_.col(col[static_cast<size_t>(j)]);
  for (Eigen::Index i = 0; i < k; ++i) x[held[static_cast<size_t>(i)]] = held_values[i];
}

}  // namespace stc
