// CPU-side packing of a symmetric sparse matrix into the texture layouts of docs/DESIGN.md
// section 9. The diagonal is stored apart (its own texture, also used by Jacobi); only the
// off-diagonal non-zeros go into Telement. Every row has one Tindex texel (start, count).
//
//  - Method A (paper): one non-zero per Telement texel, value and column packed in one texel
//    (RG32I: float bits of the value, column). One pass per non-zero: passes = longest row.
//  - Method B (paper): four non-zeros per texel (RGBA32F), rows padded to a multiple of 4,
//    two index textures Tst-a / Tst-b with the x texel coordinates (s, t) of non-zeros 0,1 and
//    2,3. Passes = ceil(longest row / 4).
//  - RowLoop (ours, the paper's "better layout" future work): Method B's 4-wide value blocks,
//    one RGBA32I index texture of 4 columns, and ONE pass in which each fragment loops over
//    its own row (GLSL 4.3 / ES 3.2 allow data-dependent loops with texelFetch). The pass count
//    no longer depends on the row length; long rows cost only their own fragments.
//
// Integer index textures keep columns exact beyond float's 2^24. Texture widths are powers of
// two so that shaders map a linear index to a texel with a shift and a mask.
#pragma once

#include "soft_tissue_cutting/solve/linear_solver.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace stc {
namespace gpu {

enum class SpmvLayout { MethodA, MethodB, RowLoop };
std::string layout_name(SpmvLayout layout);  // "method_a", "method_b", "row_loop"

// A vector of n entries in a width x height texture; entry i at (i & (width-1), i >> shift).
struct TextureShape {
  int width = 1, height = 1, shift = 0;
  long texels() const { return long(width) * height; }
};
// Square-ish (fewer reduction passes), power-of-two width at most `max_width`.
TextureShape vector_shape(long n, int max_width = 2048, int max_texture_size = 16384);

struct PackedMatrix {
  SpmvLayout layout = SpmvLayout::RowLoop;
  int rows = 0;
  TextureShape vec;                        // vectors, Tindex and the diagonal
  TextureShape elem;                       // Telement (texels) and the index textures
  int max_row = 0;                         // longest row, off-diagonal non-zeros
  int passes = 0;                          // fragment passes per SpMV
  long stored = 0;                         // Telement texels actually used
  std::vector<float> diagonal;             // vec.texels(), R32F
  std::vector<std::int32_t> tindex;        // vec.texels() x (start texel, texel count), RG32I
  std::vector<std::int32_t> telement_a;    // Method A: elem.texels() x (value bits, column)
  std::vector<float> telement4;            // B / RowLoop: elem.texels() x 4 values, RGBA32F
  std::vector<std::int32_t> tst_a, tst_b;  // B: elem.texels() x (s0, t0, s1, t1) / (s2, t2, s3, t3)
  std::vector<std::int32_t> tcols;         // RowLoop: elem.texels() x 4 columns, RGBA32I
};

PackedMatrix pack_matrix(const SparseMatrix& a, SpmvLayout layout, int max_texture_size = 16384);

}  // namespace gpu
}  // namespace stc
