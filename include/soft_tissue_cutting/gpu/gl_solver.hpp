// The "gl" backend of stc::LinearSolver (solve/linear_solver.hpp): the whole projected CG on
// the GPU in float32 textures (gl_cg.hpp), wrapped in double-precision iterative refinement
// on the CPU so it reaches tolerances float cannot (1e-10):
//   r = (b - A x)_f in double; solve A d = r on the GPU (float CG); x += d; repeat.
// The GPU holds the symmetrically Jacobi-scaled matrix D^-1/2 A D^-1/2 (unit diagonal), and
// each step's right-hand side D^-1/2 r is scaled to unit norm, so float sees O(1) numbers
// whatever the units (E in Pa, millinewton loads, 1e-9..1e3 right-hand sides).
// The residual reported is the true double one, same definition as the CPU backend:
// ||(b - A x)_f|| / ||b_f - A_fc x_c||.
// Where float32 cannot get there (refinement steps stop gaining: condition number beyond
// ~1/eps_float; the matrix does not fit the textures; non-finite values), that solve is
// finished by the CPU solver from the best x so far, with the iterations left, and
// CgResult::solved_by = "cpu", CgResult::fallback_reason says why. Running out of
// max_iterations is not a fallback: the solve is reported not converged.
#pragma once

#include "soft_tissue_cutting/gpu/matrix_layout.hpp"
#include "soft_tissue_cutting/solve/linear_solver.hpp"

#include <memory>
#include <string>

namespace stc {

struct GlSolverOptions {
  gpu::SpmvLayout layout = gpu::SpmvLayout::RowLoop;
  int check_every = 8;            // read ||r||^2 back every k GPU iterations
  double inner_reduction = 1e-5;  // float CG of one refinement step stops at this relative
                                  // recursive residual (or what the tolerance asks, if less)
  // ... or after max(inner_min_iterations, inner_dofs_factor * free DOFs) iterations: exact CG
  // needs at most n; float CG that has not got there by a few n will not.
  int inner_min_iterations = 200;
  int inner_dofs_factor = 3;
  // A refinement step "gains" when it divides the true residual by at least 2; after
  // `poor_steps` steps in a row that do not, float32 cannot reach the tolerance: fall back.
  int poor_steps = 2;
  int max_refinements = 30;  // outer double-precision refinement steps, then fall back
  bool cpu_fallback = true;  // false: report the float-limited result as not converged
  // Texture size limit for the matrix layout; 0: the device's GL_MAX_TEXTURE_SIZE (tests set
  // a small one to exercise the too-big-for-textures fallback, which ignores cpu_fallback).
  int max_texture_size = 0;
};

// Null when no GL context can be made (no EGL driver/device, or TISSUE_FORCE_NO_EGL=1);
// *why_not then says why in one line, so the caller falls back to make_cpu_solver().
std::unique_ptr<LinearSolver> make_gl_solver(std::string* why_not);
std::unique_ptr<LinearSolver> make_gl_solver(const GlSolverOptions& options, std::string* why_not);

}  // namespace stc
