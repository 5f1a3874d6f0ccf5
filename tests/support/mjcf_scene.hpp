#pragma once
// A MuJoCo model and its data from an MJCF string, through MuJoCo's own
// parser and a virtual file (for tests that need a small scene, no GL).
#include <mujoco/mujoco.h>

#include <algorithm>
#include <array>
#include <memory>
#include <string>

namespace pvb::test {

struct MjcfScene {
  std::unique_ptr<mjModel, void (*)(mjModel*)> m{nullptr, mj_deleteModel};
  std::unique_ptr<mjData, void (*)(mjData*)> d{nullptr, mj_deleteData};
  std::string error;  ///< the parser's message when m is null
};

/// Parses `xml` (mj_forward done); m is null on a parse error.
inline MjcfScene load_mjcf(const std::string& xml) {
  std::array<char, 1000> error{};
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  mj_makeEmptyFileVFS(vfs.get(), "scene.xml", static_cast<int>(xml.size()));
  std::copy(xml.begin(), xml.end(), static_cast<char*>(vfs->filedata[0]));
  MjcfScene s;
  s.m.reset(mj_loadXML("scene.xml", vfs.get(), error.data(), static_cast<int>(error.size())));
  mj_deleteVFS(vfs.get());
  s.error = error.data();
  if (!s.m) return s;
  s.d.reset(mj_makeData(s.m.get()));
  mj_forward(s.m.get(), s.d.get());
  return s;
}

}  // namespace pvb::test
