#include <mujoco/mujoco.h>

#include <cstdio>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/sim/simulator.hpp"

// MuJoCo's error and warning handlers, in a file of their own so that a
// program that only renders (bench/render_scene) links without the scene
// builder.
namespace pvb::sim {
namespace {

/// MuJoCo's message as one line: line breaks become spaces, the ends trimmed.
std::string one_line(const char* msg) {
  std::string out;
  for (const char* c = msg; c != nullptr && *c != '\0'; ++c) {
    const bool space = *c == '\n' || *c == '\r' || *c == '\t' || *c == ' ';
    if (space && (out.empty() || out.back() == ' ')) continue;
    out += space ? ' ' : *c;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

void mujoco_error(const char* msg) { throw Error("MuJoCo: " + one_line(msg)); }
void mujoco_warning(const char* msg) {
  std::fprintf(stderr, "pvbench: warning: MuJoCo: %s\n", one_line(msg).c_str());
}

}  // namespace

void install_mujoco_handlers() {
  // Only where none is set: a process may hold two copies of this library
  // (pvbench and the OpenNI2 sim:// driver plug-in, which OpenNI2 unloads at
  // shutdown), and the first one installed stays.
  if (mju_user_error == nullptr) mju_user_error = mujoco_error;
  if (mju_user_warning == nullptr) mju_user_warning = mujoco_warning;
}

}  // namespace pvb::sim
