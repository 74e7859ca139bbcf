// Full-screen fragment passes (see gl_pass.hpp).
#include "soft_tissue_cutting/gpu/gl_pass.hpp"

#include <epoxy/gl.h>

#include <stdexcept>

namespace stc {
namespace gpu {

PassRunner::PassRunner(ShaderLibrary& shaders) : shaders_(shaders) {
  // A core profile draws nothing without a bound VAO, even with no vertex attributes: the
  // quad's corners come from gl_VertexID in fullscreen_quad.vert.glsl.
  glGenVertexArrays(1, &vao_);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_DITHER);
}

PassRunner::~PassRunner() {
  clear_framebuffers();
  glDeleteVertexArrays(1, &vao_);
}

void PassRunner::finish() { glFinish(); }

void PassRunner::clear_framebuffers() {
  for (auto& f : mrt_fbos_) glDeleteFramebuffers(1, &f.second);
  mrt_fbos_.clear();
}

void PassRunner::use(const std::string& fragment_file) {
  program_ = shaders_.program(fragment_file);
  glUseProgram(program_);
  next_unit_ = 0;
}

int PassRunner::texture(const char* sampler, const Texture& t) {
  const int loc = shaders_.uniform(program_, sampler);
  if (loc < 0) return -1;  // optimised away by the compiler
  glActiveTexture(GL_TEXTURE0 + next_unit_);
  glBindTexture(GL_TEXTURE_2D, t.id());
  glUniform1i(loc, next_unit_);
  return next_unit_++;
}

void PassRunner::rebind(int unit, const Texture& t) {
  if (unit < 0) return;
  glActiveTexture(GL_TEXTURE0 + unit);
  glBindTexture(GL_TEXTURE_2D, t.id());
}

void PassRunner::set(const char* name, int v) {
  const int loc = shaders_.uniform(program_, name);
  if (loc >= 0) glUniform1i(loc, v);
}

void PassRunner::set(const char* name, float v) {
  const int loc = shaders_.uniform(program_, name);
  if (loc >= 0) glUniform1f(loc, v);
}

void PassRunner::set(const char* name, int x, int y) {
  const int loc = shaders_.uniform(program_, name);
  if (loc >= 0) glUniform2i(loc, x, y);
}

void PassRunner::draw(const Texture& target) {
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target.framebuffer());
  const GLenum buf = GL_COLOR_ATTACHMENT0;
  glDrawBuffers(1, &buf);
  glViewport(0, 0, target.width(), target.height());
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  ++passes_;
}

void PassRunner::draw(std::initializer_list<const Texture*> targets) {
  std::vector<unsigned> key;
  for (const Texture* t : targets) key.push_back(t->id());
  unsigned& fbo = mrt_fbos_[key];
  if (!fbo) {
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
    int i = 0;
    for (const Texture* t : targets)
      glFramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + i++, GL_TEXTURE_2D,
                             t->id(), 0);
    if (glCheckFramebufferStatus(GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("gl pass: multi-target framebuffer incomplete");
  }
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
  const GLenum bufs[4] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                          GL_COLOR_ATTACHMENT3};
  glDrawBuffers(GLsizei(key.size()), bufs);
  const Texture* first = *targets.begin();
  glViewport(0, 0, first->width(), first->height());
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  ++passes_;
}

}  // namespace gpu
}  // namespace stc
