// Dot products on the GPU by halving reduction passes (docs/DESIGN.md section 9): a first pass
// multiplies two vectors and sums 2x2 blocks, then 2x2 sums ping-pong down a chain of
// half-size RG32F textures; the last pass writes a caller-owned 1x1 texture, so the scalar
// stays on the GPU (alpha and beta are computed from it by shaders).
#pragma once

#include "soft_tissue_cutting/gpu/gl_pass.hpp"
#include "soft_tissue_cutting/gpu/matrix_layout.hpp"

#include <vector>

namespace stc {
namespace gpu {

class GlReduction {
 public:
  explicit GlReduction(PassRunner& runner) : runner_(runner) {}
  // Builds the chain for vectors of `shape` (no-op when unchanged).
  void configure(const TextureShape& shape);
  // target (1x1 RG32F) = (a.b, a.a). Runs passes() passes.
  void dot(const Texture& a, const Texture& b, Texture& target);
  int passes() const { return int(levels_.size()) + 1; }

 private:
  PassRunner& runner_;
  TextureShape shape_;
  std::vector<Texture> levels_;  // intermediate levels; the 1x1 level is the target
};

}  // namespace gpu
}  // namespace stc
