#include "pvb/sensor/image_codec.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <mutex>
#include <optional>

#include "pvb/common/error.hpp"

namespace pvb::sensor {
namespace {

constexpr const char* kModule = "/libpvb_imgcodecs.so";

struct Codecs {
  bool (*encode)(const std::string*, const cv::Mat*, std::vector<unsigned char>*, const std::vector<int>*) = nullptr;
  void (*decode)(const cv::Mat*, int, cv::Mat*) = nullptr;
  void (*read)(const std::string*, int, cv::Mat*) = nullptr;
  bool (*write)(const std::string*, const cv::Mat*, const std::vector<int>*) = nullptr;
};

/// PVB_MODULE_DIR when set; else the running program's ../lib when the
/// module is there (an installed tree, or a build's bin/); else where the
/// build put it.
std::string module_path() {
  if (const char* env = std::getenv("PVB_MODULE_DIR"); env != nullptr && *env != '\0') return env + std::string(kModule);
  std::array<char, 4096> exe{};
  const ssize_t n = readlink("/proc/self/exe", exe.data(), exe.size() - 1);
  if (n > 0) {
    std::string dir(exe.data(), static_cast<std::size_t>(n));
    const std::string candidate = dir.substr(0, dir.find_last_of('/')) + "/../lib" + kModule;
    if (access(candidate.c_str(), F_OK) == 0) return candidate;
  }
  return PVB_CODEC_MODULE_DIR + std::string(kModule);
}

template <typename F>
void find(void* dl, const char* name, F* f, const std::string& path) {
  *f = reinterpret_cast<F>(dlsym(dl, name));
  if (*f == nullptr) throw UnavailableError("image codecs module " + path + " lacks " + name);
}

Codecs load() {
  const std::string path = module_path();
  void* dl = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (dl == nullptr) {
    // dlerror() names the file first ("PATH: cannot open ..."): once is enough.
    const char* error = dlerror();
    std::string why = error ? error : "";
    if (why.rfind(path + ": ", 0) == 0) why.erase(0, path.size() + 2);
    throw UnavailableError("cannot load the image codecs module " + path + ": " + (why.empty() ? "unknown error" : why));
  }
  Codecs c;
  find(dl, "pvb_imencode", &c.encode, path);
  find(dl, "pvb_imdecode", &c.decode, path);
  find(dl, "pvb_imread", &c.read, path);
  find(dl, "pvb_imwrite", &c.write, path);
  return c;
}

/// The module's entry points, loaded once per process (kept loaded).
const Codecs& codecs() {
  static std::mutex mutex;
  static std::optional<Codecs> loaded;
  const std::lock_guard<std::mutex> lock(mutex);
  if (!loaded) loaded = load();
  return *loaded;
}

}  // namespace

bool imencode(const std::string& ext, const cv::Mat& image, std::vector<unsigned char>* bytes,
              const std::vector<int>& params) {
  return codecs().encode(&ext, &image, bytes, &params);
}

cv::Mat imdecode(const cv::Mat& buffer, int flags) {
  cv::Mat image;
  codecs().decode(&buffer, flags, &image);
  return image;
}

cv::Mat imread(const std::string& path, int flags) {
  cv::Mat image;
  codecs().read(&path, flags, &image);
  return image;
}

bool imwrite(const std::string& path, const cv::Mat& image, const std::vector<int>& params) {
  return codecs().write(&path, &image, &params);
}

}  // namespace pvb::sensor
