// The whole Jacobi-preconditioned projected CG in float32 on the GPU (docs/DESIGN.md section 9,
// and section 1: the paper ran only the SpMV on the GPU and read back every iteration).
// Here x, r, z, p, q live in textures, dot products are reduction passes, alpha and beta
// are 1x1 textures computed by shaders; nothing is read back inside iterate().
// It solves A d = r0 from d = 0 (GlSolver uses it for each iterative-refinement step).
#pragma once

#include "soft_tissue_cutting/gpu/gl_reduction.hpp"
#include "soft_tissue_cutting/gpu/gl_spmv.hpp"

namespace stc {
namespace gpu {

class GlCg {
 public:
  GlCg(PassRunner& runner, GlSpmv& spmv) : runner_(runner), spmv_(spmv), reduction_(runner) {}
  // Free-DOF mask (1 free, 0 constrained) and the double diagonal of A: uploads the mask
  // and M^-1 = mask / diag. Call after each GlSpmv::upload and mask change.
  void set_mask(const Vector& free_mask, const Vector& diagonal);
  // r0 must be zero on constrained DOFs. Sets d = 0, z = M^-1 r0, p = z, (r.z, r.r).
  void start(const Vector& r0);
  // `count` CG iterations, all on the GPU, no read-back.
  void iterate(int count);
  // ||r||^2 of the recursive float residual: the only scalar read back (every k iterations).
  double residual_norm2();
  Vector solution();  // d, read back at the end
  // Passes per iteration (SpMV + 2 reductions + alpha + beta + 2 updates).
  int passes_per_iteration() const { return spmv_.passes() + 2 * reduction_.passes() + 4; }

 private:
  void allocate();
  PassRunner& runner_;
  GlSpmv& spmv_;
  GlReduction reduction_;
  Texture mask_, minv_;
  Texture x_[2], r_[2], p_[2], z_, q_;
  Texture rz_[2], pq_, alpha_, beta_;  // 1x1
  int cur_ = 0;                        // index of the current x, r, p, rz
};

}  // namespace gpu
}  // namespace stc
