// Whole CG on the GPU (see gl_cg.hpp).
#include "soft_tissue_cutting/gpu/gl_cg.hpp"

#include "soft_tissue_cutting/gpu/gl_vector.hpp"

#include <epoxy/gl.h>

namespace stc {
namespace gpu {

void GlCg::allocate() {
  const TextureShape& s = spmv_.vec_shape();
  if (q_.id() && q_.width() == s.width && q_.height() == s.height) return;
  runner_.clear_framebuffers();
  for (Texture* t : {&x_[0], &x_[1], &r_[0], &r_[1], &p_[0], &p_[1], &z_, &q_})
    t->allocate(s.width, s.height, GL_R32F);
  for (Texture* t : {&rz_[0], &rz_[1], &pq_}) t->allocate(1, 1, GL_RG32F);
  for (Texture* t : {&alpha_, &beta_}) t->allocate(1, 1, GL_R32F);
  reduction_.configure(s);
}

void GlCg::set_mask(const Vector& free_mask, const Vector& diagonal) {
  allocate();
  Vector minv = Vector::Zero(free_mask.size());
  for (Eigen::Index i = 0; i < minv.size(); ++i)
    if (free_mask[i] != 0 && diagonal[i] != 0) minv[i] = 1.0 / diagonal[i];
  upload_vector(mask_, spmv_.vec_shape(), free_mask);
  upload_vector(minv_, spmv_.vec_shape(), minv);
}

void GlCg::start(const Vector& r0) {
  allocate();
  cur_ = 0;
  upload_vector(r_[0], spmv_.vec_shape(), r0);
  runner_.use("cg_init.frag.glsl");
  runner_.texture("u_r", r_[0]);
  runner_.texture("u_minv", minv_);
  runner_.draw({&x_[0], &z_, &p_[0]});
  reduction_.dot(r_[0], z_, rz_[0]);
}

void GlCg::iterate(int count) {
  for (int it = 0; it < count; ++it) {
    const int nxt = 1 - cur_;
    spmv_.multiply(p_[cur_], q_);       // q = A p
    reduction_.dot(p_[cur_], q_, pq_);  // p.q
    runner_.use("cg_alpha.frag.glsl");  // alpha = r.z / p.q
    runner_.texture("u_rz", rz_[cur_]);
    runner_.texture("u_pq", pq_);
    runner_.draw(alpha_);
    runner_.use("cg_update_xrz.frag.glsl");  // x, r, z
    runner_.texture("u_x", x_[cur_]);
    runner_.texture("u_r", r_[cur_]);
    runner_.texture("u_p", p_[cur_]);
    runner_.texture("u_q", q_);
    runner_.texture("u_mask", mask_);
    runner_.texture("u_minv", minv_);
    runner_.texture("u_alpha", alpha_);
    runner_.draw({&x_[nxt], &r_[nxt], &z_});
    reduction_.dot(r_[nxt], z_, rz_[nxt]);  // (r.z, r.r) new
    runner_.use("cg_beta.frag.glsl");       // beta = new / old
    runner_.texture("u_rz_new", rz_[nxt]);
    runner_.texture("u_rz_old", rz_[cur_]);
    runner_.draw(beta_);
    runner_.use("cg_update_p.frag.glsl");  // p = z + beta p
    runner_.texture("u_z", z_);
    runner_.texture("u_p", p_[cur_]);
    runner_.texture("u_beta", beta_);
    runner_.draw(p_[nxt]);
    cur_ = nxt;
  }
}

double GlCg::residual_norm2() { return rz_[cur_].read_float(2)[1]; }

Vector GlCg::solution() { return download_vector(x_[cur_], spmv_.rows()); }

}  // namespace gpu
}  // namespace stc
