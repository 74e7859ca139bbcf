// One fragment pass = one full-screen quad drawn into a float render target
// (docs/DESIGN.md section 9: "a fragment program run over a quad computes y = A x").
// Binds programs, input textures and targets (one or several, MRT), counts passes.
#pragma once

#include "soft_tissue_cutting/gpu/gl_texture.hpp"
#include "soft_tissue_cutting/gpu/shader_library.hpp"

#include <initializer_list>
#include <map>
#include <string>
#include <vector>

namespace stc {
namespace gpu {

class PassRunner {
 public:
  explicit PassRunner(ShaderLibrary& shaders);
  ~PassRunner();
  PassRunner(const PassRunner&) = delete;
  PassRunner& operator=(const PassRunner&) = delete;

  // Selects the program of `fragment_file` for the next draw; resets texture units.
  void use(const std::string& fragment_file);
  // Binds `t` to the next free texture unit; returns the unit (-1: sampler unused).
  int texture(const char* sampler, const Texture& t);
  // Rebinds another texture on a unit from texture() (multi-pass loops keep their uniforms).
  void rebind(int unit, const Texture& t);
  void set(const char* name, int v);
  void set(const char* name, float v);
  void set(const char* name, int x, int y);  // ivec2
  // Draws the quad over the whole of `target` (all targets must have the same size).
  void draw(const Texture& target);
  void draw(std::initializer_list<const Texture*> targets);

  long passes() const { return passes_; }
  // Waits until every queued pass has run (glFinish): for timings only.
  void finish();
  // Forget multi-target framebuffers (call before textures they use are reallocated).
  void clear_framebuffers();
  ShaderLibrary& shaders() { return shaders_; }

 private:
  ShaderLibrary& shaders_;
  unsigned vao_ = 0;
  unsigned program_ = 0;
  int next_unit_ = 0;
  long passes_ = 0;
  std::map<std::vector<unsigned>, unsigned> mrt_fbos_;
};

}  // namespace gpu
}  // namespace stc
