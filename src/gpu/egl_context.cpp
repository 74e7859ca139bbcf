// Headless EGL context creation (see egl_context.hpp). EGL and GL entry points come from
// libepoxy, so extension functions (eglQueryDevicesEXT, eglGetPlatformDisplayEXT) need no
// hand-written eglGetProcAddress table.
#include "soft_tissue_cutting/gpu/egl_context.hpp"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <sstream>
#include <vector>

namespace stc {
namespace gpu {
namespace {

// EGL displays are process-wide singletons per (platform, device): eglTerminate would kill
// every other solver's context on the same display, so terminate only with the last user.
// Function-local statics: contexts may be created during static initialisation (benchmark
// registration), before namespace-scope globals of this file are constructed.
std::mutex& display_mutex() {
  static std::mutex m;
  return m;
}

std::map<EGLDisplay, int>& display_users() {
  static std::map<EGLDisplay, int> users;
  return users;
}

void retain_display(EGLDisplay d) {
  std::lock_guard<std::mutex> lock(display_mutex());
  ++display_users()[d];
}

void release_display(EGLDisplay d) {
  std::lock_guard<std::mutex> lock(display_mutex());
  if (--display_users()[d] == 0) {
    display_users().erase(d);
    eglTerminate(d);
  }
}

bool has_extension(const char* list, const char* name) {
  if (!list) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

std::string egl_error_name(EGLint e) {
  switch (e) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE:
      return "EGL_BAD_SURFACE";
    default: {
      std::ostringstream s;
      s << "EGL error 0x" << std::hex << e;
      return s.str();
    }
  }
}

struct Candidate {
  EGLDisplay display;
  std::string origin;
};

// Devices from EGL_EXT_device_enumeration, hardware first, software (llvmpipe) last.
void device_candidates(const char* client_ext, std::vector<Candidate>& out, std::string& notes) {
  if (!has_extension(client_ext, "EGL_EXT_device_enumeration") ||
      !has_extension(client_ext, "EGL_EXT_platform_device")) {
    notes += "no EGL_EXT_device_enumeration/EGL_EXT_platform_device; ";
    return;
  }
  EGLint count = 0;
  if (!eglQueryDevicesEXT(0, nullptr, &count) || count <= 0) {
    notes += "eglQueryDevicesEXT found 0 devices; ";
    return;
  }
  std::vector<EGLDeviceEXT> devices(count);
  eglQueryDevicesEXT(count, devices.data(), &count);
  std::vector<Candidate> hardware, software;
  for (EGLint i = 0; i < count; ++i) {
    const char* dev_ext = eglQueryDeviceStringEXT(devices[i], EGL_EXTENSIONS);
    const bool is_software = has_extension(dev_ext, "EGL_MESA_device_software");
    EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
    if (d == EGL_NO_DISPLAY) continue;
    std::string origin = "EGL device " + std::to_string(i) + (is_software ? " (software)" : "");
    (is_software ? software : hardware).push_back({d, origin});
  }
  out.insert(out.end(), hardware.begin(), hardware.end());
  out.insert(out.end(), software.begin(), software.end());
}

}  // namespace

std::unique_ptr<EglContext> EglContext::create(std::string* why_not) {
  auto fail = [&](const std::string& why) -> std::unique_ptr<EglContext> {
    if (why_not) *why_not = why;
    return nullptr;
  };
  const char* force = std::getenv("TISSUE_FORCE_NO_EGL");
  if (force && std::string(force) == "1")
    return fail("GL backend disabled by TISSUE_FORCE_NO_EGL=1");

  // Client extensions (EGL_NO_DISPLAY query needs EGL 1.5 or EGL_EXT_client_extensions).
  const char* client_ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!client_ext) return fail("EGL has no client extensions (no EGL 1.5 driver installed?)");

  std::string notes;
  std::vector<Candidate> candidates;
  device_candidates(client_ext, candidates, notes);
  if (has_extension(client_ext, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay d =
        eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (d != EGL_NO_DISPLAY)
      candidates.push_back({d, "EGL surfaceless platform"});
    else
      notes += "surfaceless platform display failed (" + egl_error_name(eglGetError()) + "); ";
  } else {
    notes += "no EGL_MESA_platform_surfaceless; ";
  }
  if (candidates.empty()) return fail("no EGL display: " + notes.substr(0, notes.size() - 2));

  for (const Candidate& c : candidates) {
    EGLint major = 0, minor = 0;
    if (!eglInitialize(c.display, &major, &minor)) {
      notes += c.origin + ": eglInitialize " + egl_error_name(eglGetError()) + "; ";
      continue;
    }
    retain_display(c.display);
    const char* disp_ext = eglQueryString(c.display, EGL_EXTENSIONS);
    const bool surfaceless = has_extension(disp_ext, "EGL_KHR_surfaceless_context");
    // Desktop GL 4.3 core first (texelFetch loops, integer textures); GLES 3.2 otherwise.
    // TISSUE_GL_API=gles skips desktop GL (to test the GLES shader path on any driver).
    const char* api_env = std::getenv("TISSUE_GL_API");
    const bool gles_only = api_env && std::string(api_env) == "gles";
    for (GlApi api : {GlApi::DesktopCore, GlApi::Gles32}) {
      const bool desktop = api == GlApi::DesktopCore;
      if (desktop && gles_only) continue;
      if (!eglBindAPI(desktop ? EGL_OPENGL_API : EGL_OPENGL_ES_API)) continue;
      const EGLint config_attribs[] = {EGL_SURFACE_TYPE, surfaceless ? 0 : EGL_PBUFFER_BIT,
                                       EGL_RENDERABLE_TYPE,
                                       desktop ? EGL_OPENGL_BIT : EGL_OPENGL_ES3_BIT, EGL_NONE};
      EGLConfig config = nullptr;
      EGLint n = 0;
      if (!eglChooseConfig(c.display, config_attribs, &config, 1, &n) || n < 1) {
        notes += c.origin + (desktop ? ": no GL config; " : ": no GLES3 config; ");
        continue;
      }
      const EGLint ctx_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                    desktop ? 4 : 3,
                                    EGL_CONTEXT_MINOR_VERSION,
                                    desktop ? 3 : 2,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                    EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                    EGL_NONE};
      // EGL_CONTEXT_OPENGL_PROFILE_MASK is invalid for GLES: cut the list before it.
      std::vector<EGLint> attribs(ctx_attribs, ctx_attribs + (desktop ? 7 : 4));
      attribs.push_back(EGL_NONE);
      EGLContext ctx = eglCreateContext(c.display, config, EGL_NO_CONTEXT, attribs.data());
      if (ctx == EGL_NO_CONTEXT) {
        notes += c.origin + (desktop ? ": GL 4.3 core context " : ": GLES 3.2 context ") +
                 egl_error_name(eglGetError()) + "; ";
        continue;
      }
      EGLSurface surface = EGL_NO_SURFACE;
      if (!surfaceless) {
        const EGLint pb[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
        surface = eglCreatePbufferSurface(c.display, config, pb);
      }
      if (!eglMakeCurrent(c.display, surface, surface, ctx)) {
        notes += c.origin + ": eglMakeCurrent " + egl_error_name(eglGetError()) + "; ";
        if (surface != EGL_NO_SURFACE) eglDestroySurface(c.display, surface);
        eglDestroyContext(c.display, ctx);
        continue;
      }
      std::unique_ptr<EglContext> out(new EglContext());
      out->display_ = c.display;
      out->context_ = ctx;
      out->surface_ = surface;
      out->api_ = api;
      const char* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
      const char* v = reinterpret_cast<const char*>(glGetString(GL_VERSION));
      out->renderer_ = r ? r : "unknown";
      out->version_ = v ? v : "unknown";
      out->origin_ = c.origin;
      glGetIntegerv(GL_MAX_TEXTURE_SIZE, &out->max_texture_size_);
      return out;
    }
    release_display(c.display);
  }
  return fail("no usable EGL context: " + notes.substr(0, notes.size() - 2));
}

EglContext::~EglContext() {
  EGLDisplay d = display_;
  eglBindAPI(api_ == GlApi::DesktopCore ? EGL_OPENGL_API : EGL_OPENGL_ES_API);
  if (eglGetCurrentContext() == context_)
    eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (surface_) eglDestroySurface(d, surface_);
  eglDestroyContext(d, context_);
  release_display(d);
}

void EglContext::make_current() const {
  // The current context is tracked per client API: bind ours before asking.
  eglBindAPI(api_ == GlApi::DesktopCore ? EGL_OPENGL_API : EGL_OPENGL_ES_API);
  if (eglGetCurrentContext() != context_) eglMakeCurrent(display_, surface_, surface_, context_);
}

}  // namespace gpu
}  // namespace stc
