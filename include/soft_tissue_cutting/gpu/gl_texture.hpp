// Float / integer 2D textures used as GPU arrays (docs/DESIGN.md section 9: vectors, Telement,
// Tindex and Tst all live in textures). RAII around one GL texture name; the owning context
// must be current for every call.
#pragma once

#include <cstdint>
#include <vector>

namespace stc {
namespace gpu {

class Texture {
 public:
  Texture() = default;
  ~Texture();
  Texture(Texture&& o) noexcept;
  Texture& operator=(Texture&& o) noexcept;
  Texture(const Texture&) = delete;
  Texture& operator=(const Texture&) = delete;

  // (Re)allocates as width x height of `internal_format` (GL_R32F, GL_RG32I, ...), NEAREST
  // sampling (integer textures require it; all our fetches are texelFetch anyway). Keeps the
  // existing storage when size and format already match, so set_matrix can patch in place.
  void allocate(int width, int height, unsigned internal_format);
  // Whole-texture uploads; `data` holds width*height*channels values, row by row.
  void upload_float(const std::vector<float>& data);
  void upload_int(const std::vector<std::int32_t>& data);
  // Reads a float render target back (RGBA read works on GL and GLES): channel `c` of every texel.
  std::vector<float> read_float(int channels_wanted = 1) const;

  unsigned id() const { return id_; }
  int width() const { return width_; }
  int height() const { return height_; }
  unsigned format() const { return format_; }
  // One framebuffer with this texture as colour attachment 0, made on first use.
  unsigned framebuffer() const;

 private:
  void release();
  unsigned id_ = 0;
  mutable unsigned fbo_ = 0;
  int width_ = 0, height_ = 0;
  unsigned format_ = 0;
};

}  // namespace gpu
}  // namespace stc
