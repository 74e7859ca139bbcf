// Headless OpenGL context through EGL with no window system (docs/DESIGN.md section 9: the paper's
// CG runs in fragment programs; we need a GL context without a display server).
// Order of attempts: EGL_EXT_device_enumeration + EGL_PLATFORM_DEVICE_EXT over the devices,
// hardware first and the software device (EGL_MESA_device_software, llvmpipe) last; then the
// EGL_PLATFORM_SURFACELESS_MESA platform. On each display: desktop GL 4.3+ core, else GLES 3.2.
#pragma once

#include <memory>
#include <string>

namespace stc {
namespace gpu {

enum class GlApi { DesktopCore, Gles32 };

class EglContext {
 public:
  // Null when no EGL driver/device gives a usable context; *why_not (if given) then holds one
  // line saying why, so the caller can fall back to the CPU solver. TISSUE_FORCE_NO_EGL=1 forces
  // this path (tests of the fallback); TISSUE_GL_API=gles skips desktop GL.
  static std::unique_ptr<EglContext> create(std::string* why_not);
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  // Makes the context current on the calling thread (no-op when it already is).
  void make_current() const;
  GlApi api() const { return api_; }
  const std::string& renderer() const { return renderer_; }  // GL_RENDERER
  const std::string& version() const { return version_; }    // GL_VERSION
  const std::string& origin() const { return origin_; }      // which EGL path gave it
  int max_texture_size() const { return max_texture_size_; }

 private:
  EglContext() = default;
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  void* surface_ = nullptr;  // EGLSurface (1x1 pbuffer) or null when surfaceless
  GlApi api_ = GlApi::DesktopCore;
  std::string renderer_, version_, origin_;
  int max_texture_size_ = 0;
};

}  // namespace gpu
}  // namespace stc
