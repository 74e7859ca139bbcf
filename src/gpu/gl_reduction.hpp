// Dot products on the GPU by reduction passes (docs/DESIGN.md section 9): a first pass
// multiplies two vectors and sums kFanIn x kFanIn blocks, then block sums ping-pong down a chain
// of ever smaller RG32F textures; the last pass writes a caller-owned 1x1 texture, so the scalar
// stays on the GPU (alpha and beta are computed from it by shaders).
#pragma once

#include "gpu/gl_pass.hpp"
#include "soft_tissue_cutting/gpu/matrix_layout.hpp"

#include <vector>

namespace stc {
namespace gpu {

class GlReduction {
 public:
  explicit GlReduction(PassRunner& runner, int fan_in = kFanIn)
      : runner_(runner), fan_in_(fan_in) {}
  // Builds the chain for vectors of `shape` (no-op when unchanged).
  void configure(const TextureShape& shape);
  // target (1x1 RG32F) = (a.b, a.a). Runs passes() passes.
  void dot(const Texture& a, const Texture& b, Texture& target);
  int passes() const { return int(levels_.size()) + 1; }

  // Texels summed per output texel and axis (by default). 4 x 4 = 16 per pass instead of 2 x 2:
  // every pass costs a fixed draw overhead (a few microseconds on a real GPU, measured on an H200),
  // so a 1M-entry dot takes 5 passes instead of 10; a fragment still reads only 16 texels.
  static constexpr int kFanIn = 4;

 private:
  PassRunner& runner_;
  int fan_in_;
  TextureShape shape_;
  std::vector<Texture> levels_;  // intermediate levels; the 1x1 level is the target
};

}  // namespace gpu
}  // namespace stc
