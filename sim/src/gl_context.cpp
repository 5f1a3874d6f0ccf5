#include "pvb/sim/gl_context.hpp"

#include <dlfcn.h>
#include <mujoco/mujoco.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <mutex>

#include "pvb/common/error.hpp"

namespace pvb::sim {

struct GlContext::Api {
  void* dl = nullptr;
  void* (*create)(int, int, char*, int) = nullptr;
  int (*make_current)(void*) = nullptr;
  void (*destroy)(void*) = nullptr;
  const char* (*describe)(void*) = nullptr;
};

namespace {

std::mutex g_loaded_mutex;
GlBackend g_loaded = GlBackend::kAuto;  // kAuto: nothing loaded yet

std::string module_dir() {
  if (const char* env = std::getenv("PVB_GL_MODULE_DIR"); env != nullptr && *env != '\0') return env;
  // Next to the running program's lib/ folder (installed or build tree) ...
  std::array<char, 4096> exe{};
  const ssize_t n = readlink("/proc/self/exe", exe.data(), exe.size() - 1);
  if (n > 0) {
    std::string dir(exe.data(), static_cast<std::size_t>(n));
    dir = dir.substr(0, dir.find_last_of('/'));
    const std::string candidate = dir + "/../lib";
    if (access((candidate + "/libpvb_gl_egl.so").c_str(), F_OK) == 0 ||
        access((candidate + "/libpvb_gl_osmesa.so").c_str(), F_OK) == 0)
      return candidate;
  }
  // ... else where the build put the modules.
  return PVB_GL_MODULE_DIR;
}

std::string module_path(GlBackend b) {
  return module_dir() + (b == GlBackend::kEgl ? "/libpvb_gl_egl.so" : "/libpvb_gl_osmesa.so");
}

// Renders one frame of a trivial model with the given backend; used by the
// auto probe in a child process.
bool can_render(GlBackend b) {
  try {
    auto ctx = GlContext::create(b, 64, 64);
    char err[512] = {0};
    // A 64-texel shadow map: MuJoCo's default (4096) makes llvmpipe clear
    // 64 MB, which took the probe from about 0.05 s to 1 s.
    static const char* kXml =
        "<mujoco><visual><global offwidth='64' offheight='64'/><quality shadowsize='64' offsamples='0'/>"
        "</visual><worldbody>"
        "<geom type='box' size='1 1 1'/><camera name='c' pos='0 0 5'/></worldbody></mujoco>";
    mjVFS vfs;
    mj_defaultVFS(&vfs);
    const int len = static_cast<int>(std::char_traits<char>::length(kXml));
    if (mj_makeEmptyFileVFS(&vfs, "probe.xml", len) != 0) return false;
    std::copy(kXml, kXml + len, static_cast<char*>(vfs.filedata[vfs.nfile - 1]));
    mjModel* m = mj_loadXML("probe.xml", &vfs, err, sizeof err);
    mj_deleteVFS(&vfs);
    if (m == nullptr) return false;
    mjrContext con;
    mjr_defaultContext(&con);
    mjr_makeContext(m, &con, mjFONTSCALE_100);
    mjr_setBuffer(mjFB_OFFSCREEN, &con);
    const bool ok = con.currentBuffer == mjFB_OFFSCREEN;
    mjr_freeContext(&con);
    mj_deleteModel(m);
    return ok;
  } catch (const std::exception&) {
    return false;
  }
}

// MuJoCo calls mju_user_error on fatal GL problems and would exit(); in the
// probe child that just means "this backend does not work".
void probe_error_handler(const char*) { _exit(3); }
void probe_warning_handler(const char*) {}

bool probe_in_child(GlBackend b) {
  const pid_t pid = fork();
  if (pid < 0) return false;
  if (pid == 0) {
    mju_user_error = probe_error_handler;
    mju_user_warning = probe_warning_handler;  // never MUJOCO_LOG.TXT in the user's folder
    // silence the child: its failure is an expected outcome
    if (FILE* f = std::freopen("/dev/null", "w", stderr)) (void)f;
    _exit(can_render(b) ? 0 : 1);
  }
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return false;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace

GlBackend parse_gl_backend(const std::string& name, const std::string& field) {
  if (name == "auto") return GlBackend::kAuto;
  if (name == "egl") return GlBackend::kEgl;
  if (name == "osmesa") return GlBackend::kOsmesa;
  throw ConfigError(field, "gl backend", "one of auto, egl, osmesa", name);
}

const char* to_string(GlBackend backend) {
  switch (backend) {
    case GlBackend::kAuto: return "auto";
    case GlBackend::kEgl: return "egl";
    case GlBackend::kOsmesa: return "osmesa";
  }
  return "?";
}

GlBackend resolve_gl_backend(GlBackend requested) {
  if (requested != GlBackend::kAuto) return requested;
  {
    std::lock_guard<std::mutex> lock(g_loaded_mutex);
    if (g_loaded != GlBackend::kAuto) return g_loaded;
  }
  if (const char* env = std::getenv("MUJOCO_GL")) {
    const std::string v(env);
    if (v == "egl") return GlBackend::kEgl;
    if (v == "osmesa") return GlBackend::kOsmesa;
  }
  if (probe_in_child(GlBackend::kEgl)) return GlBackend::kEgl;
  return GlBackend::kOsmesa;
}

std::unique_ptr<GlContext> GlContext::create(GlBackend backend, int width, int height) {
  backend = resolve_gl_backend(backend);
  std::lock_guard<std::mutex> lock(g_loaded_mutex);
  if (g_loaded != GlBackend::kAuto && g_loaded != backend) {
    throw UnavailableError(std::string("GL backend ") + to_string(backend) + " requested, but this process already loaded " +
                           to_string(g_loaded) + " (MuJoCo 2.2.2 cannot use both in one process)");
  }
  const std::string path = module_path(backend);
  // RTLD_GLOBAL matters: MuJoCo 2.2.2 looks up eglGetProcAddress, then
  // OSMesaGetProcAddress, then glXGetProcAddressARB in the global scope.
  // Debian's OpenCV always brings libGLX, so a module loaded locally would
  // leave MuJoCo with GLX's loader and no current context.
  void* dl = dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL);
  if (dl == nullptr) {
    const char* why = dlerror();
    throw UnavailableError(std::string("GL backend ") + to_string(backend) + ": cannot load " + path + ": " +
                           (why ? why : "unknown error"));
  }
  g_loaded = backend;  // the module's GL library is in the process from here on
  std::unique_ptr<GlContext> ctx(new GlContext);
  ctx->api_ = std::make_unique<Api>();
  Api& api = *ctx->api_;
  api.dl = dl;
  api.create = reinterpret_cast<void* (*)(int, int, char*, int)>(dlsym(dl, "pvb_gl_create"));
  api.make_current = reinterpret_cast<int (*)(void*)>(dlsym(dl, "pvb_gl_make_current"));
  api.destroy = reinterpret_cast<void (*)(void*)>(dlsym(dl, "pvb_gl_destroy"));
  api.describe = reinterpret_cast<const char* (*)(void*)>(dlsym(dl, "pvb_gl_describe"));
  if (!api.create || !api.make_current || !api.destroy || !api.describe)
    throw UnavailableError("GL backend module " + path + " lacks the pvb_gl_* entry points");
  char err[512] = {0};
  ctx->handle_ = api.create(width, height, err, sizeof err);
  if (ctx->handle_ == nullptr)
    throw UnavailableError(std::string("GL backend ") + to_string(backend) + ": " + err);
  ctx->backend_ = backend;
  ctx->description_ = api.describe(ctx->handle_);
  return ctx;
}

GlContext::~GlContext() {
  if (api_ && handle_ != nullptr) api_->destroy(handle_);
  // The module stays loaded: MuJoCo keeps pointers into its GL library.
}

void GlContext::make_current() {
  if (api_->make_current(handle_) != 0)
    throw UnavailableError(std::string("GL backend ") + to_string(backend_) + ": cannot make the context current");
}

}  // namespace pvb::sim
