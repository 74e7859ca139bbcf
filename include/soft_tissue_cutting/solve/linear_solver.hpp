// The linear solver behind the hybrid system (docs/DESIGN.md eq. (10), section 6):
// a symmetric positive definite sparse matrix solved by Conjugate Gradient, warm-started.
// Backends: CPU (solve/) and GPU textures through headless EGL (gpu/).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace stc {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;
using Vector = Eigen::VectorXd;

struct CgSettings {
  double tolerance = 1e-10;  // relative residual ||b - A x|| / ||b|| (docs/SCENE.md "Scene file",
                             // `solver.tolerance`)
  int max_iterations = 2000;
  // A factor refactored ahead on a second thread (cpu_cg_solver.cpp, docs/DESIGN.md section 6.2)
  // is awaited at the next matrix change (true: which factor solves a step never depends on
  // timing; offline) or taken at the first change after it is ready (false: online, the loop
  // never waits for that thread; a solution then differs by rounding only).
  bool await_factor_ahead = true;
};

struct CgResult {
  int iterations = 0;   // every CG iteration of this solve, fallback included
  double residual = 0;  // final relative residual ||b - A x|| / ||b|| (true residual)
  bool converged = false;
  // The backend that produced x: "cpu" or "gl". A gl solve that float32 could not finish is
  // completed by the CPU solver: then solved_by is "cpu" and fallback_reason says why (one
  // line). Empty solved_by: nothing was solved (no free DOFs).
  std::string solved_by;
  std::string fallback_reason;
  // One line when !converged: why the solve stopped short of the tolerance.
  std::string message;
};

// The one-line reason of a solve that used up max_iterations (both backends).
std::string iteration_cap_message(const CgResult& result, const CgSettings& settings);

// Solves A x = b with some DOFs held at the values x already has on entry (Dirichlet:
// contact-imposed displacements, held free pieces): those DOFs have constrained[i] != 0 and
// the solve is the projected CG on the others, i.e. A_ff x_f = b_f - A_fc x_c. An empty
// `constrained` means none. The relative residual is measured on the free DOFs.
class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  virtual std::string backend() const = 0;             // "cpu" or "gl"
  virtual std::string renderer() const { return ""; }  // GL renderer string for "gl"
  // The preconditioner in use for the current matrix ("jacobi", "cholesky", ...); it may
  // differ from the one asked for when set_matrix had to fall back. Empty if not reported.
  virtual std::string preconditioner() const { return ""; }
  // A DOF (row of A) at which the factorization of the current matrix (without the held DOFs)
  // found it not positive definite: a mode of the system that nothing holds involves it. -1:
  // it factored, or this solver does not factor (Jacobi, gl).
  virtual int singular_dof() const { return -1; }
  // How many set_matrix calls so far refactored only the frame around the last cut
  // (framed_cholesky.hpp); 0 for a solver that does not.
  virtual int frame_updates() const { return 0; }
  // How many of those took a factor refactored ahead on a second thread (cpu_cg_solver.cpp).
  virtual int factors_taken_ahead() const { return 0; }
  // Wall time of the last set_matrix in ms (factorization, for the Cholesky preconditioner).
  virtual double setup_ms() const { return 0; }
  // A changed (new matrix after a cut, or rescaled stiffness). Symmetric, upper+lower stored.
  virtual void set_matrix(const SparseMatrix& a) = 0;
  // The same, with `held`: per DOF, nonzero = constrained in every solve until the next
  // set_matrix (free pieces held where they came free). A held piece that hangs on the rest by
  // a node or an edge makes A singular; a preconditioner built without the held DOFs does not
  // see it (cpu_cg_solver.cpp). Default: held is ignored.
  virtual void set_matrix(const SparseMatrix& a, const std::vector<std::uint8_t>& held) {
    (void)held;
    set_matrix(a);
  }
  // The same, knowing how `a` relates to the last matrix: its first `kept_rows` rows are the
  // same DOFs as the last matrix's (a cut appends the DOFs of its new nodes), and its first
  // `interface_rows` rows are the dense interface block (docs/DESIGN.md section 4). A solver
  // may then refactor only what changed (cpu_cg_solver.cpp). Default: set_matrix(a, held).
  // `changed_rows`, when given, lists every row that may differ from the last matrix's (the
  // others are bit for bit the same): the solver need not compare them.
  // `expected_rows`, when given: a factorization that cannot take `a` through its last frame
  // (a fresh one: a moved region's new model) orders these rows and a ring around them last,
  // as it orders the rows a cut changed, so the next cut there refactors that frame alone
  // (docs/DESIGN.md section 6.2): where the next cut is expected.
  struct History {
    int kept_rows = 0;
    int interface_rows = 0;
    const std::vector<int>* changed_rows = nullptr;
    const std::vector<int>* expected_rows = nullptr;
    bool await_factor_ahead = true;  // CgSettings::await_factor_ahead
  };
  virtual void set_matrix(const SparseMatrix& a, const std::vector<std::uint8_t>& held,
                          const History& history) {
    (void)history;
    set_matrix(a, held);
  }
  virtual CgResult solve(const Vector& b, Vector& x, const std::vector<std::uint8_t>& constrained,
                         const CgSettings& settings) = 0;
};

// Preconditioners of the CPU projected CG (src/solve/cpu_cg_solver.cpp explains them).
//   kJacobi:   M = diag(A), the paper's plain CG setting; ~150-300 iterations on the thigh.
//   kCholesky: M = P A^-1 P with A factored once per set_matrix (CHOLMOD). The constrained DOFs
//              are a few contact nodes, so the preconditioned operator is the identity plus a
//              term of rank <= #constrained DOFs: CG converges in about that many iterations.
//              Before CG, one direct step solves the held DOFs through the factor and a
//              capacitance system (docs/DESIGN.md eqs. (24)-(25)): usually the only iteration.
//              If A cannot be factored even with a tiny diagonal shift (indefinite), that
//              matrix is solved with Jacobi instead; preconditioner() says which is active.
enum class CgPreconditioner { kJacobi, kCholesky };

// Preconditioned projected CG in double precision on the CPU.
std::unique_ptr<LinearSolver> make_cpu_solver(CgPreconditioner preconditioner);
// The default: CgPreconditioner::kCholesky.
std::unique_ptr<LinearSolver> make_cpu_solver();

}  // namespace stc
