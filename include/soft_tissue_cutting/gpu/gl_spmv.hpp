// The matrix in textures and the fragment-pass SpMV y = A x (docs/DESIGN.md section 9), for the
// three layouts of matrix_layout.hpp. Needs the owning context current.
#pragma once

#include "soft_tissue_cutting/gpu/gl_pass.hpp"
#include "soft_tissue_cutting/gpu/gl_texture.hpp"
#include "soft_tissue_cutting/gpu/matrix_layout.hpp"

namespace stc {
namespace gpu {

class GlSpmv {
 public:
  explicit GlSpmv(PassRunner& runner) : runner_(runner) {}
  // Uploads the packed matrix; textures of unchanged size are patched in place.
  void upload(const PackedMatrix& p);
  // y = A x; x and y are distinct R32F textures of vec_shape(). Runs passes() passes.
  void multiply(const Texture& x, Texture& y);

  const Texture& diagonal() const { return diag_; }
  const TextureShape& vec_shape() const { return vec_; }
  int rows() const { return rows_; }
  int passes() const { return passes_; }
  int max_row() const { return max_row_; }
  SpmvLayout layout() const { return layout_; }

 private:
  PassRunner& runner_;
  SpmvLayout layout_ = SpmvLayout::RowLoop;
  TextureShape vec_, elem_;
  int rows_ = 0, passes_ = 0, max_row_ = 0;
  Texture diag_, tindex_, telement_, index_a_, index_b_;  // index_b_ only for Method B
  Texture partial_;  // the ping-pong partner of y for multi-pass layouts
};

}  // namespace gpu
}  // namespace stc
