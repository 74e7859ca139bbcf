// Sum reductions of fan_in x fan_in blocks (see gl_reduction.hpp).
#include "gpu/gl_reduction.hpp"

#include <epoxy/gl.h>

namespace stc {
namespace gpu {

void GlReduction::configure(const TextureShape& shape) {
  if (!levels_.empty() && shape.width == shape_.width && shape.height == shape_.height) return;
  shape_ = shape;
  levels_.clear();
  auto reduced = [this](int n) { return (n + fan_in_ - 1) / fan_in_; };
  int w = reduced(shape.width), h = reduced(shape.height);
  while (w > 1 || h > 1) {
    Texture t;
    t.allocate(w, h, GL_RG32F);
    levels_.push_back(std::move(t));
    w = reduced(w);
    h = reduced(h);
  }
}

void GlReduction::dot(const Texture& a, const Texture& b, Texture& target) {
  runner_.use("dot_first.frag.glsl");
  runner_.texture("u_a", a);
  runner_.texture("u_b", b);
  runner_.set("u_src_size", a.width(), a.height());
  runner_.set("u_fan_in", fan_in_);
  runner_.draw(levels_.empty() ? target : levels_[0]);
  if (levels_.empty()) return;
  runner_.use("reduce_sum.frag.glsl");
  const int unit = runner_.texture("u_src", levels_[0]);
  runner_.set("u_fan_in", fan_in_);
  for (std::size_t k = 0; k < levels_.size(); ++k) {
    const Texture& src = levels_[k];
    runner_.rebind(unit, src);
    runner_.set("u_src_size", src.width(), src.height());
    runner_.draw(k + 1 < levels_.size() ? levels_[k + 1] : target);
  }
}

}  // namespace gpu
}  // namespace stc
