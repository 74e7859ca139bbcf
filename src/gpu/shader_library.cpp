// Shader lookup, compilation and caching (see shader_library.hpp).
#include "soft_tissue_cutting/gpu/shader_library.hpp"

#include <epoxy/gl.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace stc {
namespace gpu {
namespace {

// The compiler or linker log of a shader or program (the getter pair differs).
template <typename GetIv, typename GetLog>
std::string info_log(GLuint object, GetIv get_iv, GetLog get_log) {
  GLint len = 0;
  get_iv(object, GL_INFO_LOG_LENGTH, &len);
  std::string log(std::size_t(len > 0 ? len : 1), '\0');
  get_log(object, len, nullptr, &log[0]);
  return log.c_str();  // drop the trailing NUL
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string version_header(GlApi api) {
  if (api == GlApi::DesktopCore) return "#version 430 core\n";
  return "#version 320 es\nprecision highp float;\nprecision highp int;\n"
         "precision highp sampler2D;\nprecision highp isampler2D;\n";
}

}  // namespace

std::string find_shader_file(const std::string& file) {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("TISSUE_SHADER_DIR")) dirs.push_back(env);
#ifdef TISSUE_SOURCE_SHADER_DIR
  dirs.push_back(TISSUE_SOURCE_SHADER_DIR);
#endif
#ifdef TISSUE_INSTALL_SHADER_DIR
  dirs.push_back(TISSUE_INSTALL_SHADER_DIR);
#endif
  std::string tried;
  for (const std::string& d : dirs) {
    const std::string path = d + "/" + file;
    if (std::ifstream(path).good()) return path;
    tried += (tried.empty() ? "" : ", ") + d;
  }
  throw std::runtime_error("shader " + file + " not found in: " + tried);
}

ShaderLibrary::~ShaderLibrary() {
  // The owning context is current when the solver is destroyed (see GlSolver).
  for (auto& p : programs_) glDeleteProgram(p.second);
}

unsigned ShaderLibrary::compile(unsigned stage, const std::string& file) {
  const std::string path = find_shader_file(file);
  const std::string src = version_header(api_) + "#line 1\n" + read_file(path);
  const GLuint sh = glCreateShader(stage);
  const char* ptr = src.c_str();
  glShaderSource(sh, 1, &ptr, nullptr);
  glCompileShader(sh);
  GLint ok = 0;
  glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    const std::string log = info_log(sh, glGetShaderiv, glGetShaderInfoLog);
    glDeleteShader(sh);
    throw std::runtime_error("shader compile failed: " + path + ": " + log);
  }
  return sh;
}

unsigned ShaderLibrary::program(const std::string& fragment_file) {
  auto it = programs_.find(fragment_file);
  if (it != programs_.end()) return it->second;
  const GLuint vs = compile(GL_VERTEX_SHADER, "fullscreen_quad.vert.glsl");
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment_file);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  const GLuint prog = glCreateProgram();
  glAttachShader(prog, vs);
  glAttachShader(prog, fs);
  glLinkProgram(prog);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(prog, GL_LINK_STATUS, &ok);
  if (!ok) {
    const std::string log = info_log(prog, glGetProgramiv, glGetProgramInfoLog);
    glDeleteProgram(prog);
    throw std::runtime_error("shader link failed: " + fragment_file + ": " + log);
  }
  programs_[fragment_file] = prog;
  return prog;
}

int ShaderLibrary::uniform(unsigned program, const char* name) {
  const auto key = std::make_pair(program, std::string(name));
  auto it = uniforms_.find(key);
  if (it != uniforms_.end()) return it->second;
  const int loc = glGetUniformLocation(program, name);
  uniforms_[key] = loc;
  return loc;
}

}  // namespace gpu
}  // namespace stc
