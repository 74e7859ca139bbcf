// GLSL programs of the texture CG (docs/DESIGN.md section 9: "a fragment program run over a quad").
// Sources live in shaders/*.glsl without a #version line; the library prepends the one that
// fits the context (desktop "430 core" or GLES "320 es" + precision), so one file serves both.
// Search order for the folder: $TISSUE_SHADER_DIR, TISSUE_SOURCE_SHADER_DIR (build tree),
// TISSUE_INSTALL_SHADER_DIR (installed package). Each program compiles once per context.
#pragma once

#include "soft_tissue_cutting/gpu/egl_context.hpp"

#include <map>
#include <string>

namespace stc {
namespace gpu {

// The first folder of the search order that holds `file`; throws with the folders tried.
std::string find_shader_file(const std::string& file);

class ShaderLibrary {
 public:
  explicit ShaderLibrary(GlApi api) : api_(api) {}
  ~ShaderLibrary();
  ShaderLibrary(const ShaderLibrary&) = delete;
  ShaderLibrary& operator=(const ShaderLibrary&) = delete;
  // Program = fullscreen_quad.vert.glsl + `fragment_file`; compiled and linked on first
  // request, cached afterwards. Throws std::runtime_error with the compiler/linker log.
  unsigned program(const std::string& fragment_file);
  // Uniform location, cached per (program, name); -1 when the uniform is unused.
  int uniform(unsigned program, const char* name);

 private:
  unsigned compile(unsigned stage, const std::string& file);
  GlApi api_;
  std::map<std::string, unsigned> programs_;
  std::map<std::pair<unsigned, std::string>, int> uniforms_;
};

}  // namespace gpu
}  // namespace stc
