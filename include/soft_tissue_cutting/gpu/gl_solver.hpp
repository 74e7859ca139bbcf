// The "gl" backend of stc::LinearSolver (solve/linear_solver.hpp): the whole projected
// Jacobi-CG on the GPU in float32 textures (gl_cg.hpp), wrapped in double-precision
// iterative refinement on the CPU so it reaches tolerances float cannot (1e-10):
//   r = (b - A x)_f in double; solve A d = r on the GPU (float CG); x += d; repeat.
// The residual reported is the true double one, same definition as the CPU backend:
// ||(b - A x)_f|| / ||b_f - A_fc x_c||.
#pragma once

#include "soft_tissue_cutting/gpu/matrix_layout.hpp"
#include "soft_tissue_cutting/solve/linear_solver.hpp"

#include <memory>
#include <string>

namespace stc {

struct GlSolverOptions {
  gpu::SpmvLayout layout = gpu::SpmvLayout::RowLoop;
  int check_every = 8;             // read ||r||^2 back every k GPU iterations
  double inner_reduction = 1e-5;   // float CG stops at this relative recursive residual...
  int stall_checks = 4;            // ...or after this many checks without a 10% improvement
  int max_refinements = 30;        // outer double-precision refinement steps
};

// Null when no GL context can be made (no EGL driver/device, or TISSUE_FORCE_NO_EGL=1);
// *why_not then says why in one line, so the caller falls back to make_cpu_solver().
std::unique_ptr<LinearSolver> make_gl_solver(std::string* why_not);
std::unique_ptr<LinearSolver> make_gl_solver(const GlSolverOptions& options, std::string* why_not);

}  // namespace stc
