#include "soft_tissue_cutting/gpu/gl_context_options.hpp"

namespace stc {

GlContextOptions gl_context_options_from(const char* force_no_egl, const char* gl_api,
                                         const char* shader_dir) {
  GlContextOptions o;
  o.disabled = force_no_egl && std::string(force_no_egl) == "1";
  o.gles_only = gl_api && std::string(gl_api) == "gles";
  if (shader_dir) o.shader_dir = shader_dir;
  return o;
}

}  // namespace stc
