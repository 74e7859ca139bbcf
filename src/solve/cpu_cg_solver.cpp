// Jacobi-preconditioned projected Conjugate Gradient in double precision (METHOD.md section 5
// step 5), the CPU backend of solve/linear_solver.hpp.
//
// Projection: constrained DOFs keep the value x has on entry. The residual and search
// directions are zeroed on them, so CG runs on A_ff x_f = b_f - A_fc x_c exactly. The
// relative residual is that of this reduced system: ||(b - A x)_f|| / ||b_f - A_fc x_c||.
// (With contact but no loads, b_f is zero while the reduced right-hand side is not, so the
// reduced norm is the meaningful denominator.) If the reduced right-hand side is zero the
// solution is x_f = 0, returned with residual 0.
#include "soft_tissue_cutting/solve/linear_solver.hpp"

#include <cmath>

namespace stc {
namespace {

class CpuCgSolver final : public LinearSolver {
 public:
  std::string backend() const override { return "cpu"; }

  void set_matrix(const SparseMatrix& a) override {
    a_ = a;
    inv_diag_ = a_.diagonal();
    for (Eigen::Index i = 0; i < inv_diag_.size(); ++i)
      inv_diag_[i] = inv_diag_[i] != 0 ? 1.0 / inv_diag_[i] : 1.0;
  }

  CgResult solve(const Vector& b, Vector& x, const std::vector<std::uint8_t>& constrained,
                 const CgSettings& settings) override {
    const Eigen::Index n = a_.rows();
    CgResult result;
    if (x.size() != n) x = Vector::Zero(n);
    Vector free_mask = Vector::Ones(n);
    if (!constrained.empty())
      for (Eigen::Index i = 0; i < n; ++i)
        if (constrained[static_cast<size_t>(i)]) free_mask[i] = 0;

    // Reduced right-hand side b_f - A_fc x_c, for the denominator.
    const Vector xc = x.cwiseProduct(Vector::Ones(n) - free_mask);
    const double rhs_norm = (b - a_ * xc).cwiseProduct(free_mask).norm();
    if (n == 0 || rhs_norm == 0) {
      x = x.cwiseProduct(Vector::Ones(n) - free_mask);  // x_f = 0 solves it exactly
      result.converged = true;
      return result;
    }
    const Vector m = inv_diag_.cwiseProduct(free_mask);  // projected Jacobi preconditioner

    // Restart from the true residual if the recursive one converged but the true one did not
    // (loss of orthogonality at very tight tolerances).
    while (true) {
      Vector r = (b - a_ * x).cwiseProduct(free_mask);
      result.residual = r.norm() / rhs_norm;
      if (result.residual <= settings.tolerance) {
        result.converged = true;
        return result;
      }
      if (result.iterations >= settings.max_iterations) return result;
      Vector z = m.cwiseProduct(r);
      Vector p = z;
      double rz = r.dot(z);
      Vector q(n);
      while (result.iterations < settings.max_iterations) {
        q.noalias() = a_ * p;
        const double pq = p.dot(q);
        if (!(pq > 0)) break;  // not SPD on the free DOFs (or breakdown): stop, report
        const double alpha = rz / pq;
        x.noalias() += alpha * p;
        r.noalias() -= alpha * q.cwiseProduct(free_mask);
        ++result.iterations;
        if (r.norm() / rhs_norm <= settings.tolerance) break;
        z = m.cwiseProduct(r);
        const double rz_new = r.dot(z);
        p = z + (rz_new / rz) * p;
        rz = rz_new;
      }
      // Final check with the true residual happens at the top of the loop; a breakdown that
      // made no progress ends here.
      const Vector r_true = (b - a_ * x).cwiseProduct(free_mask);
      const double true_res = r_true.norm() / rhs_norm;
      if (true_res <= settings.tolerance || result.iterations >= settings.max_iterations ||
          !(true_res < result.residual)) {
        result.residual = true_res;
        result.converged = true_res <= settings.tolerance;
        return result;
      }
    }
  }

 private:
  SparseMatrix a_;
  Vector inv_diag_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_cpu_solver() { return std::make_unique<CpuCgSolver>(); }

}  // namespace stc
