// Halving sum reductions (see gl_reduction.hpp).
#include "gpu/gl_reduction.hpp"

#include <epoxy/gl.h>

namespace stc {
namespace gpu {

void GlReduction::configure(const TextureShape& shape) {
  if (!levels_.empty() && shape.width == shape_.width && shape.height == shape_.height) return;
  shape_ = shape;
  levels_.clear();
  int w = (shape.width + 1) / 2, h = (shape.height + 1) / 2;
  while (w > 1 || h > 1) {
    Texture t;
    t.allocate(w, h, GL_RG32F);
    levels_.push_back(std::move(t));
    w = (w + 1) / 2;
    h = (h + 1) / 2;
  }
}

void GlReduction::dot(const Texture& a, const Texture& b, Texture& target) {
  runner_.use("dot_first.frag.glsl");
  runner_.texture("u_a", a);
  runner_.texture("u_b", b);
  runner_.set("u_src_size", a.width(), a.height());
  runner_.draw(levels_.empty() ? target : levels_[0]);
  if (levels_.empty()) return;
  runner_.use("reduce_sum.frag.glsl");
  const int unit = runner_.texture("u_src", levels_[0]);
  for (std::size_t k = 0; k < levels_.size(); ++k) {
    const Texture& src = levels_[k];
    runner_.rebind(unit, src);
    runner_.set("u_src_size", src.width(), src.height());
    runner_.draw(k + 1 < levels_.size() ? levels_[k + 1] : target);
  }
}

}  // namespace gpu
}  // namespace stc
