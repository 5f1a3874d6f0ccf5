// MuJoCo's log goes to stderr as one `pvbench: warning:` line and never to
// MUJOCO_LOG.TXT in the working directory, which MuJoCo appends to whenever
// no warning handler is set.  ctest runs each test in a process of its own
// (gtest_discover_tests), so the handlers seen here are the ones the entry
// point under test installs, not those of an earlier test.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <cstdlib>
#include <memory>
#include <string>

#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/scene_builder.hpp"

using namespace pvb;

namespace {

/// Runs `fn` with the working directory set to a new, empty folder; returns the folder.
template <typename Fn>
std::string in_fresh_folder(const std::string& name, Fn fn) {
  const std::string dir = ::testing::TempDir() + "pvb_mjlog_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str());
  char old[4096];
  if (::getcwd(old, sizeof old) == nullptr || ::chdir(dir.c_str()) != 0)
    ADD_FAILURE() << "cannot enter " << dir;
  fn();
  if (::chdir(old) != 0) ADD_FAILURE() << "cannot go back to " << old;
  return dir;
}

}  // namespace

// compile_scene is the first MuJoCo call of every command: after it, a
// MuJoCo warning (here the real one of a visual scene too small for the
// model, as with a scene larger than its room for geoms) is one stderr line.
TEST(MujocoLog, WarningAfterCompileIsOneStderrLineAndNoLogFile) {
  std::string err;
  const std::string dir = in_fresh_folder("compile", [&] {
    const scenes::Scenario s = scenes::parse_scenario("route: {waypoints_m: [[0, 0], [5, 0]]}\n", "inline");
    const sim::ModelPtr m = sim::compile_scene(sim::build_scene(s));
    std::unique_ptr<mjData, void (*)(mjData*)> d(mj_makeData(m.get()), mj_deleteData);
    mj_forward(m.get(), d.get());
    mjvScene scene;
    mjv_defaultScene(&scene);
    mjv_makeScene(m.get(), &scene, 1);  // room for one geom: MuJoCo warns
    mjvOption option;
    mjv_defaultOption(&option);
    mjvCamera camera;
    mjv_defaultCamera(&camera);
    ::testing::internal::CaptureStderr();
    mjv_updateScene(m.get(), d.get(), &option, nullptr, &camera, mjCAT_ALL, &scene);
    err = ::testing::internal::GetCapturedStderr();
    mjv_freeScene(&scene);
  });
  EXPECT_NE(::access((dir + "/MUJOCO_LOG.TXT").c_str(), F_OK), 0) << "MuJoCo wrote its log file into " << dir;
  EXPECT_EQ(err.rfind("pvbench: warning: MuJoCo: Pre-allocated visual geom buffer is full", 0), 0u) << err;
  EXPECT_EQ(err.find('\n'), err.size() - 1) << "one line: " << err;
  if (!::testing::Test::HasFailure()) std::system(("rm -rf " + dir).c_str());
}
