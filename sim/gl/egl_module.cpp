// EGL off-screen backend.  Prefers a real device (EGL_EXT_platform_device:
// the GPU's driver where one exists), then Mesa's surfaceless platform (CPU
// rendering with llvmpipe on machines without a GPU).  MuJoCo 2.2.2 renders
// with the compatibility profile into its own framebuffer object, so the
// context needs no surface.
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>

#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <string>

#include "gl_module_api.h"

namespace {

struct EglContext {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  std::string description;
};

void set_err(char* err, int len, const std::string& msg) {
  if (err != nullptr && len > 0) {
    std::snprintf(err, static_cast<size_t>(len), "%s", msg.c_str());
  }
}

std::string hex(EGLint v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04x", static_cast<unsigned>(v));
  return buf;
}

bool has_ext(const char* list, const char* name) {
  if (list == nullptr) return false;
  const size_t n = std::strlen(name);
  for (const char* p = std::strstr(list, name); p != nullptr; p = std::strstr(p + 1, name)) {
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  }
  return false;
}

// Contexts alive per display.  eglGetPlatformDisplay returns the same
// display for every context of a process, and eglTerminate ends all of its
// contexts, so the display is terminated only when its last context goes.
std::mutex g_displays_mutex;
std::map<EGLDisplay, int> g_display_contexts;

// Adds `delta` to the display's count of live contexts (+1 on create, -1 on
// destroy, 0 after a failed create) and terminates it when none is left.
void count_display_contexts(EGLDisplay dpy, int delta) {
  const std::lock_guard<std::mutex> lock(g_displays_mutex);
  int& live = g_display_contexts[dpy];
  live += delta;
  if (live <= 0) {
    g_display_contexts.erase(dpy);
    eglTerminate(dpy);
  }
}

// Tries to initialise a display; returns EGL_NO_DISPLAY on failure.
EGLDisplay try_init(EGLDisplay dpy) {
  if (dpy == EGL_NO_DISPLAY) return EGL_NO_DISPLAY;
  EGLint major = 0, minor = 0;
  if (eglInitialize(dpy, &major, &minor) != EGL_TRUE) return EGL_NO_DISPLAY;
  return dpy;
}

EGLDisplay open_display(std::string* platform) {
  const char* client_ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display != nullptr && has_ext(client_ext, "EGL_EXT_platform_device")) {
    auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    auto query_device_string =
        reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
    EGLDeviceEXT devices[16];
    EGLint n = 0;
    if (query_devices != nullptr && query_devices(16, devices, &n) == EGL_TRUE) {
      for (EGLint i = 0; i < n; ++i) {
        // Mesa lists a software device too; skip it here so a real GPU wins,
        // and fall back to the surfaceless platform below.
        const char* dev_ext = query_device_string ? query_device_string(devices[i], EGL_EXTENSIONS) : nullptr;
        if (has_ext(dev_ext, "EGL_MESA_device_software")) continue;
        EGLDisplay dpy = try_init(get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr));
        if (dpy != EGL_NO_DISPLAY) {
          *platform = "device " + std::to_string(i);
          return dpy;
        }
      }
    }
  }
  if (get_platform_display != nullptr && has_ext(client_ext, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay dpy = try_init(get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr));
    if (dpy != EGL_NO_DISPLAY) {
      *platform = "surfaceless";
      return dpy;
    }
  }
  EGLDisplay dpy = try_init(eglGetDisplay(EGL_DEFAULT_DISPLAY));
  if (dpy != EGL_NO_DISPLAY) *platform = "default display";
  return dpy;
}

}  // namespace

extern "C" void* pvb_gl_create(int width, int height, char* err, int err_len) {
  (void)width;
  (void)height;  // rendering goes to MuJoCo's own framebuffer object
  std::string platform;
  EGLDisplay dpy = open_display(&platform);
  if (dpy == EGL_NO_DISPLAY) {
    set_err(err, err_len, "EGL: no display could be initialised (error " + hex(eglGetError()) + ")");
    return nullptr;
  }
  const EGLint config_attribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RED_SIZE, 8,  EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8,
                                   EGL_ALPHA_SIZE, 8, EGL_DEPTH_SIZE, 24, EGL_STENCIL_SIZE, 8,
                                   EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint n_configs = 0;
  if (eglChooseConfig(dpy, config_attribs, &config, 1, &n_configs) != EGL_TRUE || n_configs < 1) {
    // surfaceless displays may expose configs without a depth buffer only;
    // MuJoCo renders into its own FBO, so any OpenGL config will do
    const EGLint any_attribs[] = {EGL_SURFACE_TYPE, 0, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    if (eglChooseConfig(dpy, any_attribs, &config, 1, &n_configs) != EGL_TRUE || n_configs < 1) {
      set_err(err, err_len, "EGL (" + platform + "): no OpenGL config (error " + hex(eglGetError()) + ")");
      count_display_contexts(dpy, 0);
      return nullptr;
    }
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
    set_err(err, err_len, "EGL (" + platform + "): desktop OpenGL API unavailable");
    count_display_contexts(dpy, 0);
    return nullptr;
  }
  // MuJoCo 2.2.2 uses fixed-function GL: ask for a compatibility profile.
  const EGLint ctx_attribs[] = {EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT,
                                EGL_NONE};
  EGLContext ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, ctx_attribs);
  if (ctx == EGL_NO_CONTEXT) ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, nullptr);
  if (ctx == EGL_NO_CONTEXT) {
    set_err(err, err_len, "EGL (" + platform + "): cannot create a context (error " + hex(eglGetError()) + ")");
    count_display_contexts(dpy, 0);
    return nullptr;
  }
  if (eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx) != EGL_TRUE) {
    set_err(err, err_len,
            "EGL (" + platform + "): cannot make a surfaceless context current (error " + hex(eglGetError()) + ")");
    eglDestroyContext(dpy, ctx);
    count_display_contexts(dpy, 0);
    return nullptr;
  }
  count_display_contexts(dpy, +1);
  auto* c = new EglContext{dpy, ctx, {}};
  auto get_string = reinterpret_cast<const GLubyte* (*)(GLenum)>(eglGetProcAddress("glGetString"));
  const char* vendor = get_string ? reinterpret_cast<const char*>(get_string(GL_VENDOR)) : nullptr;
  const char* renderer = get_string ? reinterpret_cast<const char*>(get_string(GL_RENDERER)) : nullptr;
  c->description = "egl (" + platform + "): " + (vendor ? vendor : "?") + " / " + (renderer ? renderer : "?");
  return c;
}

extern "C" int pvb_gl_make_current(void* h) {
  auto* c = static_cast<EglContext*>(h);
  return eglMakeCurrent(c->display, EGL_NO_SURFACE, EGL_NO_SURFACE, c->context) == EGL_TRUE ? 0 : -1;
}

extern "C" void pvb_gl_destroy(void* h) {
  auto* c = static_cast<EglContext*>(h);
  if (c == nullptr) return;
  if (eglGetCurrentContext() == c->context)
    eglMakeCurrent(c->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(c->display, c->context);
  count_display_contexts(c->display, -1);
  delete c;
}

extern "C" const char* pvb_gl_describe(void* h) { return static_cast<EglContext*>(h)->description.c_str(); }
