// Preconditioned projected Conjugate Gradient in double precision (docs/DESIGN.md section 6),
// the CPU backend of solve/linear_solver.hpp.
//
// Projection: constrained DOFs keep the value x has on entry. The residual and search
// directions are zeroed on them, so CG runs on A_ff x_f = b_f - A_fc x_c exactly. The
// relative residual is that of this reduced system: ||(b - A x)_f|| / ||b_f - A_fc x_c||.
// (With contact but no loads, b_f is zero while the reduced right-hand side is not, so the
// reduced norm is the meaningful denominator.) If the reduced right-hand side is zero the
// solution is x_f = 0, returned with residual 0.
//
// Preconditioners z = M r (r is zero on constrained DOFs, and so is z):
//   Jacobi:   M = P diag(A)^-1 P.
//   Cholesky: M = P A^-1 P, A = L L^T factored by CHOLMOD in set_matrix, i.e. only when the
//             hybrid matrix changes (construction, cuts, E changes; docs/DESIGN.md sections 4, 6);
//             a cut that changed nothing outside the frame kept by the last factorization
//             refactors that frame alone (framed_cholesky.hpp, docs/DESIGN.md section 6.2).
//             On the free DOFs M is (A^-1)_ff = S^-1 with S = A_ff - A_fc A_cc^-1 A_cf (block
//             inverse), so the preconditioned operator is S^-1 A_ff = I + S^-1 A_fc A_cc^-1 A_cf:
//             the identity plus rank <= #constrained DOFs. CG therefore needs at most
//             #constrained + 1 iterations in exact arithmetic, whatever the condition of A, and
//             none without constraints beyond the one exact step. Contact touches a few nodes.
//             Before any CG iteration, the held DOFs are solved for directly through the same
//             factor and a k x k capacitance system (docs/DESIGN.md eqs. (24)-(25),
//             held_dof_solve.cpp), counted as one iteration; CG runs only if its true residual
//             misses the tolerance.
// A held free piece (simulation.cpp) makes A singular: its rigid modes are unanchored, though
// every DOF of it is constrained. When the caller names the held DOFs (set_matrix(a, held)),
// the factor is of D = [A_kk 0; 0 diag(A)_hh] (docs/DESIGN.md eq. (30)), A with the held rows
// and columns cleared but for their diagonal (k = the kept DOFs, h = the held ones): SPD, no
// shift, and since every
// held DOF is constrained in every solve, (A_kk^-1)_ff is again the inverse of the Schur
// complement on the free DOFs (block inverse within k), so the iteration count stays
// #constrained-DOFs-of-k + 1. A held DOF that a solve leaves free gets Jacobi (D's own rows:
// the preconditioner stays SPD). The held rows stay in D, so a change of what is held changes
// D's rows, not its size, and the frame of section 6.2 can take it like a cut's. Without the held
// DOFs named, A + d*diag(A) with tiny d is the second attempt: it keeps (A^-1)_ff of the anchored
// rest to ~d*cond(A) when the piece is its own connected block of A, but a piece held by a hinge (a
// node or an edge shared with the rest) couples its near-null modes, amplified by 1/d, into the
// free DOFs: with slivers (cond ~1e8) the preconditioner degrades to Jacobi-like and CG stalls
// short of 1e-10. An indefinite A (no SPD factor even shifted) falls back to Jacobi for that
// matrix; preconditioner() reports it.
//
// The direct step (held_dof_solve) needs the factor of A itself, or of D when every held DOF
// is constrained (their values move to the right-hand side).
#include "soft_tissue_cutting/solve/framed_cholesky.hpp"
#include "soft_tissue_cutting/solve/held_dof_solve.hpp"
#include "soft_tissue_cutting/solve/linear_solver.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"
#include "solve/blas_guard.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace stc {
namespace {

// Relative diagonal shift of the second factorization attempt: far above the rounding of a
// zero pivot (~1e-16 n), far below anything that would slow the preconditioned CG.
constexpr double kShift = 1e-9;

// The frame a factorization after a cut keeps for the next cuts (framed_cholesky.hpp): the
// rows the cut changed and two rings of their neighbours where those stay within
// kWiderFrameShare of the cap below, else one ring (the next sweep splits the same tets or
// their neighbours, and a slow blade's often those of the next ring too: the organ liver, a
// blade moving 0.05 mm per step and each sweep cut at its step, 172 cuts: outside a one-ring
// frame 85 times, outside a two-ring one 44 times, the cutting steps' solve median 12.1 ->
// 5.7 ms with two rings up to the whole cap, 7.3 ms up to 0.6 of it). Wider frames cost every
// cut more: on the bench's 1 mm strokes, where 22 of the organ's 31 cuts fell inside one ring
// already, two rings up to the whole cap took the solve median 3.6 -> 5.8 ms and the maximum
// 27 -> 37 ms; up to 0.6 of it, 3.6 ms and 27 ms. Its dense Schur complement costs |B|^3/3
// flops per cut and 3 |B|^2 doubles (L_BB, W, the factor of S'). A frame is kept while that is
// no more than a refactorization costs (CHOLMOD's flop count of the last one), never past half
// the block, at least up to kMinFrame DOFs (~72 MFlop, a few ms) and never past kMaxFrame
// (~35 MB, ~20 ms). The thigh refactors cheaply and keeps the 600-DOF cap (a soak-like random
// walk on it reached 900 DOFs: 20 MB, ~10 ms, more than its whole refactorization; a flat
// 1200-DOF cap grew the thigh soak's RSS by 70 MB); at 206k tets a refactorization costs
// 60-140 ms, and with the conformed cut borders a cut changes more rows: a 600-DOF cap sent
// most cuts there to a full refactorization (cutting step median 30 -> 74 ms). A change of E
// changes every row: no frame.
// A frame that later cuts grew (their new DOFs, and the rows outside it they changed, which
// join it: eq. (28)) is kept up to update_limit (below). Past kPrefactorShare of the cap, it
// is refactored ahead, on a second thread, around the cut that grew it (docs/DESIGN.md section
// 6.2, "Refactored ahead"): the next cut updates that factor's fresh frame instead of this
// grown one. Before that thread, frames were kept up to 0.75 of the cap (each cut's dense
// refactorization then cost at most 0.42 of the sparse one, and a refactorization framed the
// latest changes afresh: organ liver's follow stroke offline, 172 cuts, up to the whole cap 16
// refactorizations and 3.5 GFlop in frame updates, up to 0.75 19 and 2.5 GFlop); with it, a
// grown frame is reframed off the loop's thread, and where the cap is what a refactorization
// costs, the whole cap takes a few more cuts through the frame (offline organ stroke 19 -> 17
// refactorizations). Online organ follow stroke, three runs each: cutting steps' solve median
// 5.0-6.1 -> 4.1-4.8 ms with the thread at 0.65 (0.5: 4.2-5.6, more threads started).
constexpr int kFrameRings = 2;
constexpr double kWiderFrameShare = 0.6;
constexpr double kUpdateFrameShare = 0.75;
constexpr double kPrefactorShare = 0.65;
constexpr int kMinFrame = 600;
constexpr int kMaxFrame = 1200;
int max_frame(Eigen::Index rows, double refactor_flops) {
  const int worth = static_cast<int>(std::cbrt(3 * std::max(refactor_flops, 0.0)));
  return std::min({static_cast<int>(rows / 2), kMaxFrame, std::max(kMinFrame, worth)});
}
// Whether a refactorization costs at least a dense frame of the whole cap (the organ liver, 200k
// tets): then frames are kept up to the cap and refactored ahead (kPrefactorShare). Not the
// thigh, whose cap is kMinFrame: a 600-DOF frame's dense factor, ~4 ms, costs twice its
// refactorization (the whole cap and the thread there took its cutting median 3.3 -> 3.8 ms and
// its maximum 9-12 -> 13-15 ms).
// A small operation part whose cap is rows / 2, below the floor, is not dear either (the thigh
// soak's random cuts met that now and then: threads started for ~2 ms refactorizations, and the
// soak's RSS grew past its limit once, 72 MB).
bool refactor_is_dear(Eigen::Index rows, double refactor_flops) {
  const double worth = std::cbrt(3 * std::max(refactor_flops, 0.0));
  return worth >= kMinFrame && worth >= max_frame(rows, refactor_flops);
}
// The largest frame an update may make.
int update_limit(Eigen::Index rows, double refactor_flops) {
  const int cap = max_frame(rows, refactor_flops);
  return refactor_is_dear(rows, refactor_flops) ? cap : static_cast<int>(kUpdateFrameShare * cap);
}

// `out` holds `a`'s rows before `first` already, bit for bit: the rest of `a` is copied after
// them (both compressed; else, or if the two disagree where the rows meet, all of `a`).
void copy_rows_after(const SparseMatrix& a, Eigen::Index first, SparseMatrix& out) {
  if (!a.isCompressed() || !out.isCompressed() || first > out.rows() || first > a.rows() ||
      out.outerIndexPtr()[first] != a.outerIndexPtr()[first]) {
    out = a;
    return;
  }
  const int base = a.outerIndexPtr()[first];
  const int nnz = static_cast<int>(a.nonZeros());
  out.conservativeResize(a.rows(), a.cols());
  out.data().resize(nnz, 0.125);  // room for the next cuts' entries
  std::copy(a.outerIndexPtr() + first, a.outerIndexPtr() + a.outerSize() + 1,
            out.outerIndexPtr() + first);
  std::copy(a.innerIndexPtr() + base, a.innerIndexPtr() + nnz, out.innerIndexPtr() + base);
  std::copy(a.valuePtr() + base, a.valuePtr() + nnz, out.valuePtr() + base);
}

std::string format_residual(double r) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", r);
  return buf;
}

class CpuCgSolver final : public LinearSolver {
 public:
  explicit CpuCgSolver(CgPreconditioner wanted) : wanted_(wanted) {}
  ~CpuCgSolver() override { take_prefactor(); }  // the thread reads this solver's block

  std::string backend() const override { return "cpu"; }
  std::string preconditioner() const override { return active_; }
  double setup_ms() const override { return setup_ms_; }
  int frame_updates() const override { return frame_updates_; }
  int factors_taken_ahead() const override { return taken_ahead_; }
  // Found on demand (one more factorization), so a cut whose first factor fails only until
  // its free pieces are held pays nothing for it.
  int singular_dof() const override {
    if (!factor_failed_) return -1;
    if (!singular_dof_) {
      const int c = SparseCholesky::first_failing_column(block());
      singular_dof_ = c;  // D's rows are A's
    }
    return *singular_dof_;
  }

  void set_matrix(const SparseMatrix& a) override { set_matrix(a, {}); }

  void set_matrix(const SparseMatrix& a, const std::vector<std::uint8_t>& held) override {
    set_matrix(a, held, History{});
  }

  void set_matrix(const SparseMatrix& a, const std::vector<std::uint8_t>& held,
                  const History& history) override {
    const auto t0 = std::chrono::steady_clock::now();
    // The thread refactoring ahead copies the block it factors first (long done by now, a
    // step later): the block may change below.
    if (prefactor_copied_.valid()) prefactor_copied_.wait();
    // The factor refactored ahead of an earlier block: awaited, or (online) taken if ready.
    std::unique_ptr<FramedCholesky> ahead;
    if (prefactor_.valid() &&
        (history.await_factor_ahead ||
         prefactor_.wait_for(std::chrono::seconds(0)) == std::future_status::ready))
      ahead = take_prefactor();
    if (!held.empty() && static_cast<Eigen::Index>(held.size()) != a.rows())
      throw std::invalid_argument("set_matrix: held has " + std::to_string(held.size()) +
                                  " entries for " + std::to_string(a.rows()) + " DOFs");
    const Vector old_held_mask = held_mask_;
    const Eigen::Index old_rows = a_.rows();
    const bool was_held = any_held_;
    // The leading rows that are the last matrix's, bit for bit (History::changed_rows names
    // every other row): on the hybrid matrix the dense interface block, most of its entries.
    const std::optional<Eigen::Index> same_until = unchanged_leading_rows(a, history);
    if (same_until) {
      // Only the rows from there on are copied (the organ liver's whole matrix, ~290k entries:
      // 0.6 ms a cut). The changed rows are known, so no frame is chosen by comparing blocks.
      copy_rows_after(a, *same_until, a_);
      previous_.resize(0, 0);
    } else {
      // The last block, kept (what the next frame is chosen against by comparison): swapped,
      // not copied, and the arrays of the one before it are re-used for the new matrix.
      previous_.swap(was_held ? decoupled_ : a_);
      a_ = a;
    }
    held_mask_ = Vector::Zero(a_.rows());
    for (size_t i = 0; i < held.size(); ++i)
      if (held[i]) held_mask_[static_cast<Eigen::Index>(i)] = 1;
    any_held_ = !held_mask_.isZero(0);
    if (any_held_) {
      // D's rows before the first that A or the held set changed (a row whose DOF was held or
      // let go, and its neighbours) are the last D's.
      Eigen::Index d_same = same_until && was_held ? *same_until : 0;
      for (Eigen::Index r = 0; r < d_same; ++r)  // d_same <= the old size
        if (held_mask_[r] != old_held_mask[r]) {
          const int row_start = a_.outerIndexPtr()[r];  // its lowest neighbour (sorted columns)
          d_same = std::min(r, row_start < a_.outerIndexPtr()[r + 1]
                                   ? static_cast<Eigen::Index>(a_.innerIndexPtr()[row_start])
                                   : r);
        }
      decoupled_rows_after(a_, d_same, decoupled_);
    } else {
      decoupled_.resize(0, 0);
    }
    inv_diag_ = a_.diagonal();
    for (Eigen::Index i = 0; i < inv_diag_.size(); ++i)
      inv_diag_[i] = inv_diag_[i] != 0 ? 1.0 / inv_diag_[i] : 1.0;
    held_.reset();
    // Rows a cut changed: the last solution does not solve the new system (a new model from a
    // region move, or new held DOFs, may well be solved by it: the warm start is checked).
    matrix_is_new_ = history.changed_rows && !history.changed_rows->empty();
    last_.reset();
    factor_failed_ = false;
    singular_dof_.reset();
    // The block's rows are the same DOFs as before when the matrix's are (held or not: a held
    // DOF keeps its row in D): then a cut within the last frame refactors the frame alone.
    const bool same_rows = chol_ && old_rows > 0 && history.kept_rows >= old_rows;
    auto in_range = [this](const std::vector<int>& rows) {
      std::vector<int> out;
      for (int r : rows)
        if (r >= 0 && r < a_.rows()) out.push_back(r);
      return out;
    };
    // The rows changed since the factorization, when known (a DOF held or let go changes its
    // row of D and its neighbours'); where the next change is expected.
    std::optional<std::vector<int>> changed, expected;
    if (same_rows && history.changed_rows) {
      changed = in_range(*history.changed_rows);
      for (Eigen::Index r = 0; r < old_rows; ++r)
        if (held_mask_[r] != old_held_mask[r])
          for (SparseMatrix::InnerIterator it(a_, r); it; ++it)  // r itself among them
            changed->push_back(static_cast<int>(it.index()));
    }
    if (history.expected_rows) expected = in_range(*history.expected_rows);
    // The rows changed since the block the factor ahead was made of: this change's and those
    // of the changes made while it ran (unknown, or other DOFs: it cannot take this block).
    if (ahead || prefactor_.valid()) {
      if (changed && ahead_changed_)
        ahead_changed_->insert(ahead_changed_->end(), changed->begin(), changed->end());
      else
        ahead_changed_.reset();
    }
    if (wanted_ == CgPreconditioner::kCholesky) {
      factor(same_rows, history.interface_rows, previous_, changed, expected, std::move(ahead));
    } else {
      chol_.reset();
      active_ = "jacobi";
    }
    setup_ms_ =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }

  CgResult solve(const Vector& b, Vector& x, const std::vector<std::uint8_t>& constrained,
                 const CgSettings& settings) override {
    // The last solve's system asked again with its answer as the start (an idle step, a blade
    // held still): that answer, without a product with A. A system that changed since (the
    // blade moved) is not solved by the last answer either: no warm-start check then, straight
    // to the direct step (one product with A a step instead of two: ~0.25 ms on the organ
    // liver). A new matrix's first solve checks the warm start as before (a moved region's
    // model may well be solved by it, docs/DESIGN.md section 10a).
    if (last_ && last_->result.converged && last_->result.residual <= settings.tolerance &&
        last_->b.size() == b.size() && last_->x.size() == x.size() && last_->b == b &&
        last_->x == x && last_->constrained == constrained) {
      CgResult same = last_->result;
      same.iterations = 0;
      return same;
    }
    // A cut's matrix is not solved by the last solution either: no product to find out.
    const bool check_warm = !last_ && !matrix_is_new_;
    CgResult result = solve_system(b, x, constrained, settings, check_warm);
    last_ = LastSolve{b, x, constrained, result};
    return result;
  }

 private:
  CgResult solve_system(const Vector& b, Vector& x, const std::vector<std::uint8_t>& constrained,
                        const CgSettings& settings, bool check_warm) {
    const Eigen::Index n = a_.rows();
    CgResult result;
    result.solved_by = "cpu";
    if (x.size() != n) x = Vector::Zero(n);
    Vector free_mask = Vector::Ones(n);
    std::vector<int> held;
    if (!constrained.empty())
      for (Eigen::Index i = 0; i < n; ++i)
        if (constrained[static_cast<size_t>(i)]) {
          free_mask[i] = 0;
          held.push_back(static_cast<int>(i));
        }

    // Reduced right-hand side b_f - A_fc x_c, for the denominator: A is symmetric, so A_fc x_c
    // is read from the held rows alone (no whole product for a few held DOFs).
    Vector reduced = b;
    for (int c : held)
      for (SparseMatrix::InnerIterator it(a_, c); it; ++it) reduced[it.col()] -= it.value() * x[c];
    const double rhs_norm = reduced.cwiseProduct(free_mask).norm();
    if (n == 0 || rhs_norm == 0) {
      x = x.cwiseProduct(Vector::Ones(n) - free_mask);  // x_f = 0 solves it exactly
      result.converged = true;
      return result;
    }
    const Vector m = inv_diag_.cwiseProduct(free_mask);  // projected Jacobi preconditioner
    const auto precondition = [&](const Vector& r) -> Vector {
      if (!chol_) return m.cwiseProduct(r);
      // With held DOFs, D's rows are Jacobi on a held DOF this solve leaves free.
      return chol_->solve(r).cwiseProduct(free_mask);
    };

    // With the factor of A: the direct solve through the capacitance on the held DOFs
    // (docs/DESIGN.md eqs. (24)-(25)), counted as one iteration, unless the warm start
    // already solves the system. Its true residual decides; CG goes on from it otherwise.
    // With the factor of D (held pieces' DOFs named in set_matrix, all of them constrained
    // here): the same on the kept DOFs, the held ones' values moved to the right-hand side
    // (b_k - A_kh x_h). Projected CG would need as many iterations as this solve constrains
    // kept DOFs (a press after a cut freed pieces: 9 iterations, 5.5 ms on the organ liver).
    const bool kept_direct = any_held_ && held_mask_.cwiseProduct(free_mask).isZero(0);
    if (chol_ && (!any_held_ || kept_direct) && settings.max_iterations > 0) {
      const double warm = !check_warm ? std::numeric_limits<double>::infinity()
                                      : (b - a_ * x).cwiseProduct(free_mask).norm() / rhs_norm;
      if (warm > settings.tolerance) {
        Vector direct = x;
        if (!any_held_) {
          held_.solve(*chol_, b, held, direct);
        } else {
          // D's held rows decouple: their values move to the right-hand side of the kept
          // rows, and their own rows give them back (reset exactly below). A is symmetric, so
          // A (x .* held) is read from the held rows alone (a product with all of A cost
          // ~0.5 ms a cut on the organ liver for a few held pieces).
          Vector rhs = b;
          for (Eigen::Index c = 0; c < n; ++c)
            if (held_mask_[c] != 0 && x[c] != 0)
              for (SparseMatrix::InnerIterator it(a_, c); it; ++it)
                rhs[it.index()] -= it.value() * x[c];
          std::vector<int> held_k;  // the constrained kept DOFs
          for (int c : held)
            if (held_mask_[c] == 0) held_k.push_back(c);
          for (Eigen::Index i = 0; i < n; ++i)
            if (held_mask_[i] != 0) rhs[i] = decoupled_.coeff(i, i) * x[i];
          held_.solve(*chol_, rhs, held_k, direct);
          for (Eigen::Index i = 0; i < n; ++i)
            if (held_mask_[i] != 0) direct[i] = x[i];
        }
        result.iterations = 1;
        const double res = (b - a_ * direct).cwiseProduct(free_mask).norm() / rhs_norm;
        if (res < warm) x = std::move(direct);
        result.residual = std::min(res, warm);
        if (result.residual <= settings.tolerance) {
          result.converged = true;
          return result;
        }
      }
    }

    // Restart from the true residual if the recursive one converged but the true one did not
    // (loss of orthogonality at very tight tolerances).
    while (true) {
      Vector r = (b - a_ * x).cwiseProduct(free_mask);
      result.residual = r.norm() / rhs_norm;
      if (result.residual <= settings.tolerance) {
        result.converged = true;
        return result;
      }
      if (result.iterations >= settings.max_iterations) {
        result.message = iteration_cap_message(result, settings);
        return result;
      }
      const Vector pass_start = x;  // kept if this pass only makes things worse
      Vector z = precondition(r);
      Vector p = z;
      double rz = r.dot(z);
      Vector q(n);
      while (result.iterations < settings.max_iterations && rz > 0) {
        q.noalias() = a_ * p;
        const double pq = p.dot(q);
        if (!(pq > 0)) break;  // not SPD on the free DOFs (or breakdown): stop, report
        const double alpha = rz / pq;
        x.noalias() += alpha * p;
        r.noalias() -= alpha * q.cwiseProduct(free_mask);
        ++result.iterations;
        if (r.norm() / rhs_norm <= settings.tolerance) break;
        z = precondition(r);
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
        // Never hand back an iterate worse than the one this pass began from (on a system
        // that is not positive definite CG can end far off: a relative residual of 116 was
        // published as the tissue's shape for a minute in a soak). A NaN counts as worse.
        const bool reverted = !(true_res <= result.residual);
        if (reverted)
          x = pass_start;
        else
          result.residual = true_res;
        result.converged = result.residual <= settings.tolerance;
        if (!result.converged)
          result.message = result.iterations >= settings.max_iterations
                               ? iteration_cap_message(result, settings)
                               : "CG stopped gaining at relative residual " +
                                     format_residual(result.residual) + " (tolerance " +
                                     format_residual(settings.tolerance) +
                                     "): too ill-conditioned for double precision, or not "
                                     "positive definite on the free DOFs";
        if (reverted)
          result.message += "; the last iterate was worse (" + format_residual(true_res) +
                            "), the one before this pass is kept";
        return result;
      }
    }
  }

  // The matrix to factor: A, or D with the held DOFs decoupled.
  const SparseMatrix& block() const { return any_held_ ? decoupled_ : a_; }

  // The first row of `a` that may differ from the last matrix's (none: unknown): the lowest
  // changed row, or the old size. Needs the rows to be the same DOFs (History::kept_rows).
  std::optional<Eigen::Index> unchanged_leading_rows(const SparseMatrix& a,
                                                     const History& history) const {
    if (!history.changed_rows || a_.rows() == 0 || history.kept_rows < a_.rows() ||
        a.rows() < a_.rows())
      return std::nullopt;
    Eigen::Index first = a_.rows();
    for (int r : *history.changed_rows)
      if (r >= 0) first = std::min(first, static_cast<Eigen::Index>(r));
    return first;
  }

  // D of A (held_mask_ set): the held rows and columns cleared but for the diagonal (1 where
  // that is not positive), written over `out`'s rows from `first` on (its rows before are D's
  // already). Row by row: each row's columns stay sorted, so the compressed arrays are written
  // directly (no triplets, no sort), into `out`'s arrays (a new matrix every cut page-faulted
  // in megabytes of fresh memory each time).
  void decoupled_rows_after(const SparseMatrix& a, Eigen::Index first, SparseMatrix& out) const {
    const Eigen::Index n = a.rows();
    if (first <= 0 || !out.isCompressed() || out.rows() < first) {
      first = 0;
      out.resize(n, n);
    } else {
      out.conservativeResize(n, n);
    }
    int k = out.outerIndexPtr()[first];
    // At most A's entries of those rows and a diagonal each (1/8 more room for the next cuts).
    out.data().resize(k + (a.nonZeros() - a.outerIndexPtr()[first]) + (n - first), 0.125);
    int* outer = out.outerIndexPtr();
    int* inner = out.innerIndexPtr();
    double* value = out.valuePtr();
    for (Eigen::Index i = first; i < n; ++i) {
      outer[i] = k;
      if (held_mask_[i] != 0) {
        double d = 0;
        for (SparseMatrix::InnerIterator it(a, i); it; ++it)
          if (it.index() == i) d = it.value();
        inner[k] = static_cast<int>(i);
        value[k++] = d > 0 ? d : 1.0;
        continue;
      }
      for (SparseMatrix::InnerIterator it(a, i); it; ++it)
        if (held_mask_[it.index()] == 0)
          inner[k] = static_cast<int>(it.index()), value[k++] = it.value();
    }
    outer[n] = k;
    out.data().resize(k);
  }

  // A (or D) itself, else it + kShift diag (a held free piece not named), else Jacobi stays
  // active. same_rows: the block's leading rows are the last block's DOFs, so the last factor
  // may take it by refactoring its frame (docs/DESIGN.md section 6.2), and else the new factor
  // keeps a frame around what changed since `previous` (the last block); its first `interface`
  // rows are the dense interface block.
  // ahead: an earlier block's factor refactored ahead (kPrefactorShare), if one was and is
  // ready; ahead_changed_ lists the rows changed since that block.
  void factor(bool same_rows, int interface, const SparseMatrix& previous,
              const std::optional<std::vector<int>>& changed,
              const std::optional<std::vector<int>>& expected,
              std::unique_ptr<FramedCholesky> ahead) {
    const SparseMatrix& block = this->block();
    if (block.rows() == 0) {
      chol_.reset();
      active_ = "jacobi";
      return;
    }
    const int dense = interface;  // the interface block's rows (D's rows are A's)
    // The factor refactored ahead differs from this block in the rows changed since its own.
    const auto take_ahead = [&](std::unique_ptr<FramedCholesky> f) {
      if (!f || !same_rows || !ahead_changed_ || active_ != "cholesky" ||
          !f->update(block, &*ahead_changed_, update_limit(block.rows(), f->factor_flops())))
        return false;
      chol_ = std::move(f);
      changed_since_factor_ = std::move(ahead_changed_);
      ahead_changed_.reset();
      ++frame_updates_;
      ++taken_ahead_;
      return true;
    };
    if (take_ahead(std::move(ahead))) return;
    // Every row changed since the factorization: this change's, and the earlier updates'.
    if (changed && changed_since_factor_)
      changed_since_factor_->insert(changed_since_factor_->end(), changed->begin(), changed->end());
    else
      changed_since_factor_.reset();
    if (same_rows && active_ == "cholesky") {
      const int cap = max_frame(block.rows(), chol_->factor_flops());
      if (chol_->update(block, changed_since_factor_ ? &*changed_since_factor_ : nullptr,
                        update_limit(block.rows(), chol_->factor_flops()))) {
        ++frame_updates_;
        // Refactored ahead when the frame or its extra rows fill up (a fresh factor with a
        // small frame, a moved region's, meets the extra-row limit long before the cap).
        const bool filling = chol_->frame_size() > kPrefactorShare * cap ||
                             chol_->extra_rows() > kPrefactorShare * FramedCholesky::kMaxExtraRows;
        if (changed && !prefactor_.valid() && filling &&
            refactor_is_dear(block.rows(), chol_->factor_flops()))
          prefactor(frame_for(block, previous, changed, dense, cap));
        return;
      }
    }
    // The grown frame is full: the factor still being refactored ahead is awaited now (what
    // is left of it costs less than a refactorization here).
    if (prefactor_.valid() && take_ahead(take_prefactor())) return;
    // The last factorization's cost stands for this one's (the block changed by one cut).
    const double refactor_flops = chol_ ? chol_->factor_flops() : 0;
    const int cap = max_frame(block.rows(), refactor_flops);
    std::vector<int> frame;
    if (same_rows && (changed || (previous.rows() > 0 && previous.rows() <= block.rows())))
      frame = frame_for(block, previous, changed, dense, cap);
    else if (expected && !expected->empty())  // a fresh factor: frame where a cut is expected
      frame = FramedCholesky::frame_around(block, *expected, dense, 1);
    if (static_cast<int>(frame.size()) > cap) frame.clear();
    chol_.reset();
    active_ = "jacobi";
    try {
      chol_ = std::make_unique<FramedCholesky>(block, frame);
      active_ = "cholesky";
      changed_since_factor_.emplace();
      return;
    } catch (const std::runtime_error&) {
      factor_failed_ = true;
    }
    SparseMatrix shifted = block;
    const double dmax = block.diagonal().cwiseAbs().maxCoeff();
    for (Eigen::Index i = 0; i < shifted.rows(); ++i) {
      const double d = block.coeff(i, i);
      shifted.coeffRef(i, i) += kShift * (d > 0 ? d : dmax);
    }
    try {
      chol_ = std::make_unique<FramedCholesky>(shifted, std::vector<int>{});
      active_ = "cholesky (shifted)";
    } catch (const std::runtime_error&) {
      chol_.reset();
    }
  }

  // The frame a factorization after a change keeps: the rows changed since `previous` (this
  // change's, when known) and kFrameRings rings of neighbours, fewer where more would pass
  // kWiderFrameShare of the cap. `dense`: the interface block's rows (never grow it).
  static std::vector<int> frame_for(const SparseMatrix& block, const SparseMatrix& previous,
                                    const std::optional<std::vector<int>>& changed, int dense,
                                    int cap) {
    std::vector<int> frame;
    for (int rings = kFrameRings; rings >= 1; --rings) {
      frame = changed ? FramedCholesky::frame_around(block, *changed, dense, rings)
                      : FramedCholesky::frame_around_changes(previous, block, dense, rings);
      if (frame.size() <= (rings > 1 ? kWiderFrameShare : 1.0) * cap) break;
    }
    return frame;
  }

  // Refactors the present block with `frame` on a second thread. The thread copies the block
  // first (prefactor_copied_, which the next set_matrix awaits before it changes the block),
  // and the factor keeps that copy.
  void prefactor(std::vector<int> frame) {
    if (frame.empty()) return;
    const SparseMatrix& block = this->block();
    auto copied = std::make_shared<std::promise<void>>();
    try {
      prefactor_copied_ = copied->get_future();
      prefactor_ = std::async(std::launch::async, [&block, copied, frame = std::move(frame)]() {
        settle_openmp_on_this_thread();  // CHOLMOD at full speed on this thread (blas_guard.hpp)
        std::unique_ptr<FramedCholesky> f;
        bool told = false;
        try {
          SparseMatrix own = block;
          copied->set_value();
          told = true;
          f = std::make_unique<FramedCholesky>(std::move(own), frame);
        } catch (const std::exception&) {  // not positive definite, out of memory: the loop's
        }                                  // own refactorization meets it and says so
        if (!told) copied->set_value();
        return f;
      });
      ahead_changed_.emplace();           // the factor ahead is of this block
    } catch (const std::system_error&) {  // no thread to be had: the loop refactors when due
      prefactor_copied_ = {};
    }
  }

  // The factor refactored ahead, waiting for it (null if none was started or it failed).
  // Offline (History::await_factor_ahead) one is taken at every set_matrix, so which factor a
  // step uses never depends on timing.
  std::unique_ptr<FramedCholesky> take_prefactor() {
    if (!prefactor_.valid()) return nullptr;
    prefactor_copied_ = {};
    return prefactor_.get();
  }

  CgPreconditioner wanted_;
  SparseMatrix a_;
  Vector inv_diag_;
  std::unique_ptr<FramedCholesky> chol_;
  std::future<std::unique_ptr<FramedCholesky>> prefactor_;  // a block's, refactored ahead
  std::future<void> prefactor_copied_;  // ready once that thread has its own copy of the block
  // The rows changed since the block prefactor_ factors (none: it cannot take the present one).
  std::optional<std::vector<int>> ahead_changed_;
  SparseMatrix decoupled_;  // D when some DOFs are held (else the block is a_ itself)
  // The block's rows that changed since chol_ factored it (none: unknown, compared instead).
  std::optional<std::vector<int>> changed_since_factor_;
  SparseMatrix previous_;       // the block before the last set_matrix (its arrays reused)
  bool matrix_is_new_ = false;  // set by a cut: its first solve checks no warm start
  // The last solve since set_matrix: its system (b, constrained DOFs), its answer x and result.
  struct LastSolve {
    Vector b, x;
    std::vector<std::uint8_t> constrained;
    CgResult result;
  };
  std::optional<LastSolve> last_;
  // y = A^-1 b and A^-1 e_c of held DOFs for the current matrix (D's and its kept DOFs'
  // when some DOFs are held).
  HeldDofSolve held_;
  bool any_held_ = false;  // some DOFs named held in set_matrix: the factor is D's
  Vector held_mask_;       // per DOF: 1 = held (named in set_matrix)
  std::string active_ = "jacobi";
  bool factor_failed_ = false;               // A (or D) has no Cholesky factor
  mutable std::optional<int> singular_dof_;  // where, once asked (singular_dof())
  double setup_ms_ = 0;
  int frame_updates_ = 0;
  int taken_ahead_ = 0;
};

}  // namespace

std::string iteration_cap_message(const CgResult& result, const CgSettings& settings) {
  return "max_iterations (" + std::to_string(settings.max_iterations) +
         ") reached at relative residual " + format_residual(result.residual) + " (tolerance " +
         format_residual(settings.tolerance) + ")";
}

std::unique_ptr<LinearSolver> make_cpu_solver(CgPreconditioner preconditioner) {
  return std::make_unique<CpuCgSolver>(preconditioner);
}

std::unique_ptr<LinearSolver> make_cpu_solver() {
  return make_cpu_solver(CgPreconditioner::kCholesky);
}

}  // namespace stc
