// Texture SpMV (see gl_spmv.hpp).
#include "gpu/gl_spmv.hpp"

#include <epoxy/gl.h>

#include <stdexcept>

namespace stc {
namespace gpu {

void GlSpmv::upload(const PackedMatrix& p) {
  runner_.clear_framebuffers();
  layout_ = p.layout;
  vec_ = p.vec;
  elem_ = p.elem;
  rows_ = p.rows;
  passes_ = p.passes;
  max_row_ = p.max_row;
  diag_.allocate(vec_.width, vec_.height, GL_R32F);
  diag_.upload_float(p.diagonal);
  tindex_.allocate(vec_.width, vec_.height, GL_RG32I);
  tindex_.upload_int(p.tindex);
  switch (layout_) {
    case SpmvLayout::MethodA:
      telement_.allocate(elem_.width, elem_.height, GL_RG32I);
      telement_.upload_int(p.telement_a);
      break;
    case SpmvLayout::MethodB:
      telement_.allocate(elem_.width, elem_.height, GL_RGBA32F);
      telement_.upload_float(p.telement4);
      index_a_.allocate(elem_.width, elem_.height, GL_RGBA32I);
      index_a_.upload_int(p.tst_a);
      index_b_.allocate(elem_.width, elem_.height, GL_RGBA32I);
      index_b_.upload_int(p.tst_b);
      break;
    case SpmvLayout::RowLoop:
      telement_.allocate(elem_.width, elem_.height, GL_RGBA32F);
      telement_.upload_float(p.telement4);
      index_a_.allocate(elem_.width, elem_.height, GL_RGBA32I);
      index_a_.upload_int(p.tcols);
      break;
  }
  if (passes_ > 1) partial_.allocate(vec_.width, vec_.height, GL_R32F);
}

void GlSpmv::multiply(const Texture& x, Texture& y) {
  if (x.id() == y.id()) throw std::runtime_error("gl spmv: x and y must differ");
  if (layout_ == SpmvLayout::RowLoop) {
    runner_.use("spmv_row_loop.frag.glsl");
    runner_.texture("u_x", x);
    runner_.texture("u_diag", diag_);
    runner_.texture("u_tindex", tindex_);
    runner_.texture("u_telement", telement_);
    runner_.texture("u_tcols", index_a_);
    runner_.set("u_vec_shift", vec_.shift);
    runner_.set("u_elem_shift", elem_.shift);
    runner_.draw(y);
    return;
  }
  // Multi-pass: ping-pong between y and partial_, arranged so that the last pass writes y.
  // Uniforms and textures are bound once; each pass only swaps u_prev and sets u_pass.
  const bool method_a = layout_ == SpmvLayout::MethodA;
  runner_.use(method_a ? "spmv_method_a.frag.glsl" : "spmv_method_b.frag.glsl");
  runner_.texture("u_x", x);
  runner_.texture("u_diag", diag_);
  const int prev_unit = runner_.texture("u_prev", diag_);  // pass 0 ignores u_prev
  runner_.texture("u_tindex", tindex_);
  runner_.texture("u_telement", telement_);
  if (method_a) {
    runner_.set("u_vec_shift", vec_.shift);
  } else {
    runner_.texture("u_tst_a", index_a_);
    runner_.texture("u_tst_b", index_b_);
  }
  runner_.set("u_elem_shift", elem_.shift);
  for (int k = 0; k < passes_; ++k) {
    Texture& target = (passes_ - 1 - k) % 2 == 0 ? y : partial_;
    if (k > 0) runner_.rebind(prev_unit, (passes_ - k) % 2 == 0 ? y : partial_);
    runner_.set("u_pass", k);
    runner_.draw(target);
  }
}

}  // namespace gpu
}  // namespace stc
