// OSMesa off-screen backend: Mesa's software renderer into a client buffer.
// MuJoCo renders into its own framebuffer object; the client buffer only has
// to exist for the context to be current.
#include <GL/osmesa.h>

#include <cstdio>
#include <string>
#include <vector>

#include "gl_module_api.h"

namespace {
struct OsMesaContext {
  OSMesaContext context = nullptr;
  std::vector<unsigned char> buffer;
  int width = 0;
  int height = 0;
  std::string description;
};
}  // namespace

extern "C" void* pvb_gl_create(int width, int height, char* err, int err_len) {
  const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 8,
                         OSMESA_PROFILE, OSMESA_COMPAT_PROFILE, 0};
  OSMesaContext ctx = OSMesaCreateContextAttribs(attribs, nullptr);
  if (ctx == nullptr) ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (ctx == nullptr) {
    if (err != nullptr && err_len > 0) std::snprintf(err, static_cast<size_t>(err_len), "OSMesa: cannot create a context");
    return nullptr;
  }
  auto* c = new OsMesaContext;
  c->context = ctx;
  c->width = width > 0 ? width : 1;
  c->height = height > 0 ? height : 1;
  c->buffer.resize(static_cast<size_t>(c->width) * static_cast<size_t>(c->height) * 4u);
  if (OSMesaMakeCurrent(ctx, c->buffer.data(), GL_UNSIGNED_BYTE, c->width, c->height) != GL_TRUE) {
    if (err != nullptr && err_len > 0) std::snprintf(err, static_cast<size_t>(err_len), "OSMesa: cannot make the context current");
    OSMesaDestroyContext(ctx);
    delete c;
    return nullptr;
  }
  const char* vendor = reinterpret_cast<const char*>(glGetString(GL_VENDOR));
  const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  c->description = std::string("osmesa: ") + (vendor ? vendor : "?") + " / " + (renderer ? renderer : "?");
  return c;
}

extern "C" int pvb_gl_make_current(void* h) {
  auto* c = static_cast<OsMesaContext*>(h);
  return OSMesaMakeCurrent(c->context, c->buffer.data(), GL_UNSIGNED_BYTE, c->width, c->height) == GL_TRUE ? 0 : -1;
}

extern "C" void pvb_gl_destroy(void* h) {
  auto* c = static_cast<OsMesaContext*>(h);
  if (c == nullptr) return;
  OSMesaDestroyContext(c->context);
  delete c;
}

extern "C" const char* pvb_gl_describe(void* h) { return static_cast<OsMesaContext*>(h)->description.c_str(); }
