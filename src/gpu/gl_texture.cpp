// Texture RAII and transfers (see gl_texture.hpp).
#include "soft_tissue_cutting/gpu/gl_texture.hpp"

#include <epoxy/gl.h>

#include <stdexcept>
#include <string>
#include <utility>

namespace stc {
namespace gpu {
namespace {

struct FormatInfo {
  GLenum format;  // client format for uploads
  GLenum type;
  int channels;
};

FormatInfo format_info(GLenum internal) {
  switch (internal) {
    case GL_R32F:
      return {GL_RED, GL_FLOAT, 1};
    case GL_RG32F:
      return {GL_RG, GL_FLOAT, 2};
    case GL_RGBA32F:
      return {GL_RGBA, GL_FLOAT, 4};
    case GL_R32I:
      return {GL_RED_INTEGER, GL_INT, 1};
    case GL_RG32I:
      return {GL_RG_INTEGER, GL_INT, 2};
    case GL_RGBA32I:
      return {GL_RGBA_INTEGER, GL_INT, 4};
    default:
      throw std::runtime_error("gl texture: unsupported internal format");
  }
}

}  // namespace

Texture::~Texture() { release(); }

Texture::Texture(Texture&& o) noexcept { *this = std::move(o); }

Texture& Texture::operator=(Texture&& o) noexcept {
  if (this != &o) {
    release();
    std::swap(id_, o.id_);
    std::swap(fbo_, o.fbo_);
    width_ = o.width_;
    height_ = o.height_;
    format_ = o.format_;
  }
  return *this;
}

void Texture::release() {
  if (fbo_) glDeleteFramebuffers(1, &fbo_);
  if (id_) glDeleteTextures(1, &id_);
  id_ = fbo_ = 0;
  width_ = height_ = 0;
}

void Texture::allocate(int width, int height, unsigned internal_format) {
  if (id_ && width == width_ && height == height_ && internal_format == format_) return;
  release();
  glGenTextures(1, &id_);
  glBindTexture(GL_TEXTURE_2D, id_);
  glTexStorage2D(GL_TEXTURE_2D, 1, internal_format, width, height);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  width_ = width;
  height_ = height;
  format_ = internal_format;
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR)
    throw std::runtime_error("gl texture: allocation of " + std::to_string(width) + "x" +
                             std::to_string(height) + " failed, GL error " + std::to_string(err));
}

void Texture::upload_float(const std::vector<float>& data) {
  const FormatInfo f = format_info(format_);
  if (f.type != GL_FLOAT || data.size() != std::size_t(width_) * height_ * f.channels)
    throw std::runtime_error("gl texture: float upload size/format mismatch");
  glBindTexture(GL_TEXTURE_2D, id_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width_, height_, f.format, f.type, data.data());
}

void Texture::upload_int(const std::vector<std::int32_t>& data) {
  const FormatInfo f = format_info(format_);
  if (f.type != GL_INT || data.size() != std::size_t(width_) * height_ * f.channels)
    throw std::runtime_error("gl texture: int upload size/format mismatch");
  glBindTexture(GL_TEXTURE_2D, id_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width_, height_, f.format, f.type, data.data());
}

unsigned Texture::framebuffer() const {
  if (!fbo_) {
    glGenFramebuffers(1, &fbo_);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, id_, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error(
          "gl texture: float render target incomplete (no color_buffer_float?)");
  }
  return fbo_;
}

std::vector<float> Texture::read_float(int channels_wanted) const {
  // GL_RGBA + GL_FLOAT is the read format every float colour buffer supports (GLES included).
  std::vector<float> rgba(std::size_t(width_) * height_ * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer());
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_FLOAT, rgba.data());
  std::vector<float> out(std::size_t(width_) * height_ * channels_wanted);
  for (std::size_t i = 0; i < std::size_t(width_) * height_; ++i)
    for (int c = 0; c < channels_wanted; ++c) out[i * channels_wanted + c] = rgba[i * 4 + c];
  return out;
}

}  // namespace gpu
}  // namespace stc
