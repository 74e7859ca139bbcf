// Vectors as R32F textures (docs/DESIGN.md section 9: "vectors are float textures"): entry i at
// texel (i & (width-1), i >> shift); padding texels hold 0 so reductions may sum them.
#pragma once

#include "soft_tissue_cutting/gpu/gl_texture.hpp"
#include "soft_tissue_cutting/gpu/matrix_layout.hpp"

namespace stc {
namespace gpu {

// Allocates `t` in `shape` (R32F) and uploads v (rounded to float), zero padding.
void upload_vector(Texture& t, const TextureShape& shape, const Vector& v);
// Reads the first n entries back to double.
Vector download_vector(const Texture& t, int n);

}  // namespace gpu
}  // namespace stc
