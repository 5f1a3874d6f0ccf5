#pragma once
// Off-screen GL contexts for MuJoCo, one backend per process.
//
// Each backend is a plug-in module (libpvb_gl_egl.so, libpvb_gl_osmesa.so)
// loaded with dlopen, so a process loads libEGL or libOSMesa, never both.
// `auto` decides in a short-lived child process, so the parent has loaded
// nothing when it makes its one real choice.
#include <memory>
#include <string>

namespace pvb::sim {

enum class GlBackend { kAuto, kEgl, kOsmesa };

/// "auto", "egl" or "osmesa"; throws ConfigError(field, ...) otherwise.
GlBackend parse_gl_backend(const std::string& name, const std::string& field = "--gl");
const char* to_string(GlBackend backend);

/// Picks a working backend for kAuto: $MUJOCO_GL when it names egl or osmesa,
/// else EGL if a child process can render a MuJoCo frame with it, else OSMesa.
/// Other values are returned unchanged.
GlBackend resolve_gl_backend(GlBackend requested);

class GlContext {
 public:
  /// Loads the backend's module and makes a context current on this thread.
  /// Throws UnavailableError with the backend's reason when it cannot, or
  /// when this process already loaded the other backend.
  static std::unique_ptr<GlContext> create(GlBackend backend, int width, int height);
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  void make_current();
  GlBackend backend() const { return backend_; }
  /// e.g. "egl (surfaceless): Mesa / llvmpipe (LLVM 15.0.6, 256 bits)".
  const std::string& description() const { return description_; }

 private:
  GlContext() = default;
  struct Api;
  std::unique_ptr<Api> api_;
  void* handle_ = nullptr;
  GlBackend backend_ = GlBackend::kEgl;
  std::string description_;
};

}  // namespace pvb::sim
