// Packing into Method A / Method B / RowLoop textures (see matrix_layout.hpp).
#include "soft_tissue_cutting/gpu/matrix_layout.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace stc {
namespace gpu {
namespace {

int log2_exact(int w) {
  int s = 0;
  while ((1 << s) < w) ++s;
  return s;
}

// Width w (power of two, <= max_width) and enough rows for `count` texels.
TextureShape shape_for(long count, int w, int max_texture_size) {
  count = std::max(count, 1L);
  TextureShape s;
  s.width = w;
  s.shift = log2_exact(w);
  s.height = int((count + w - 1) / w);
  if (s.height > max_texture_size)
    throw std::runtime_error("gpu matrix layout: " + std::to_string(count) +
                             " texels exceed the texture size limit");
  return s;
}

std::int32_t float_bits(float f) {
  std::int32_t i;
  std::memcpy(&i, &f, sizeof i);
  return i;
}

}  // namespace

std::string layout_name(SpmvLayout layout) {
  switch (layout) {
    case SpmvLayout::MethodA:
      return "method_a";
    case SpmvLayout::MethodB:
      return "method_b";
    case SpmvLayout::RowLoop:
      return "row_loop";
  }
  return "?";
}

TextureShape vector_shape(long n, int max_width, int max_texture_size) {
  int w = 1;
  while (w < max_width && long(w) * w < n) w *= 2;
  return shape_for(n, w, max_texture_size);
}

PackedMatrix pack_matrix(const SparseMatrix& a, SpmvLayout layout, int max_texture_size) {
  if (a.rows() != a.cols()) throw std::runtime_error("gpu matrix layout: matrix not square");
  PackedMatrix p;
  p.layout = layout;
  p.rows = int(a.rows());
  p.vec = vector_shape(p.rows, 2048, max_texture_size);
  p.diagonal.assign(p.vec.texels(), 0.f);
  p.tindex.assign(p.vec.texels() * 2, 0);
  const int group = layout == SpmvLayout::MethodA ? 1 : 4;  // non-zeros per Telement texel

  // Row lengths (off-diagonal) and Telement start of each row, in texels.
  std::vector<long> start(p.rows + 1, 0);
  for (int i = 0; i < p.rows; ++i) {
    int len = 0;
    for (SparseMatrix::InnerIterator it(a, i); it; ++it)
      if (it.col() != i) ++len;
    p.max_row = std::max(p.max_row, len);
    start[i + 1] = start[i] + (len + group - 1) / group;
  }
  p.stored = start[p.rows];
  if (p.stored > 0x7fffffffL) throw std::runtime_error("gpu matrix layout: too many non-zeros");
  // Telement width: 2048 texels, widened (power of two) when the height would overflow.
  int ew = 2048;
  while (ew < max_texture_size && (p.stored + ew - 1) / ew > max_texture_size) ew *= 2;
  p.elem = shape_for(p.stored, ew, max_texture_size);
  const long et = p.elem.texels();
  switch (layout) {
    case SpmvLayout::MethodA:
      p.telement_a.assign(et * 2, 0);
      p.passes = std::max(1, p.max_row);
      break;
    case SpmvLayout::MethodB:
      p.telement4.assign(et * 4, 0.f);
      p.tst_a.assign(et * 4, 0);  // padding: coordinate (0,0) with value 0 adds 0 * x[0]
      p.tst_b.assign(et * 4, 0);
      p.passes = std::max(1, (p.max_row + 3) / 4);
      break;
    case SpmvLayout::RowLoop:
      p.telement4.assign(et * 4, 0.f);
      p.tcols.assign(et * 4, 0);
      p.passes = 1;
      break;
  }

  const int vmask = p.vec.width - 1;
  for (int i = 0; i < p.rows; ++i) {
    p.tindex[2 * i] = std::int32_t(start[i]);
    p.tindex[2 * i + 1] = std::int32_t(start[i + 1] - start[i]);
    long k = 0;  // off-diagonal non-zero number within the row
    for (SparseMatrix::InnerIterator it(a, i); it; ++it) {
      const int c = int(it.col());
      if (c == i) {
        p.diagonal[i] += float(it.value());
        continue;
      }
      const long texel = start[i] + k / group;
      const int lane = int(k % group);
      ++k;
      switch (layout) {
        case SpmvLayout::MethodA:
          p.telement_a[2 * texel] = float_bits(float(it.value()));
          p.telement_a[2 * texel + 1] = c;
          break;
        case SpmvLayout::MethodB: {
          p.telement4[4 * texel + lane] = float(it.value());
          auto& tst = lane < 2 ? p.tst_a : p.tst_b;
          tst[4 * texel + 2 * (lane % 2)] = c & vmask;
          tst[4 * texel + 2 * (lane % 2) + 1] = c >> p.vec.shift;
          break;
        }
        case SpmvLayout::RowLoop:
          p.telement4[4 * texel + lane] = float(it.value());
          p.tcols[4 * texel + lane] = c;
          break;
      }
    }
  }
  return p;
}

}  // namespace gpu
}  // namespace stc
