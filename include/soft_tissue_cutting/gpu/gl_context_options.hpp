// How the gl backend makes its context and finds its shaders: options, never environment
// variables read inside the core. The apps (`tissue solve`, tissue_node) map their environment
// (TISSUE_FORCE_NO_EGL=1, TISSUE_GL_API=gles, TISSUE_SHADER_DIR) through
// gl_context_options_from(std::getenv(...)); tests set the fields directly.
#pragma once

#include <string>

namespace stc {

struct GlContextOptions {
  bool disabled = false;   // no context: the gl backend reports itself unavailable
  bool gles_only = false;  // skip desktop GL 4.3 (tests the GLES 3.2 shader path on any driver)
  std::string shader_dir;  // searched first for shaders/*.glsl (then build tree, install)
};

// The options from the values of TISSUE_FORCE_NO_EGL, TISSUE_GL_API and TISSUE_SHADER_DIR
// (null: unset): "1" disables, "gles" means GLES only, a non-empty folder is searched first.
GlContextOptions gl_context_options_from(const char* force_no_egl, const char* gl_api,
                                         const char* shader_dir);

}  // namespace stc
