#pragma once
// Runs the built pvbench program from a test and captures what it printed.
// Output goes to a file named after the process id: ctest runs test
// processes in parallel.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pvb/common/text.hpp"

namespace pvb::test {

inline const std::string& pvbench_path() {
  static const std::string path = std::string(PVB_BINARY_DIR) + "/bin/pvbench";
  return path;
}

struct RunResult {
  int code = -1;       ///< exit status (-1 if killed by a signal)
  std::string output;  ///< stdout and stderr together
};

/// Runs `pvbench ARGS` through the shell (ARGS is not quoted).
inline RunResult run_pvbench(const std::string& args) {
  const std::string log = ::testing::TempDir() + "pvb_run_" + std::to_string(::getpid()) + ".txt";
  const int status = std::system((pvbench_path() + " " + args + " > " + log + " 2>&1").c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(log)};
}

/// Runs `ENV pvbench ARGS` from the source folder, so that relative paths
/// such as sim://scenes/... resolve as in the README; ENV goes before the
/// program (variable assignments, or a wrapper such as `timeout 300`).
inline RunResult run_pvbench_from_source(const std::string& env, const std::string& args) {
  const std::string log = ::testing::TempDir() + "pvb_run_" + std::to_string(::getpid()) + ".txt";
  const std::string cmd =
      "cd " + std::string(PVB_SOURCE_DIR) + " && " + env + " " + pvbench_path() + " " + args + " > " + log + " 2>&1";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(log)};
}

/// Runs `pvbench ARGS` with every file it writes capped at `max_kib` KiB
/// (a disk that fills up): SIGXFSZ ignored, so a write past the cap fails
/// with EFBIG instead of killing the program.
inline RunResult run_pvbench_with_file_limit(const std::string& args, int max_kib) {
  const std::string log = ::testing::TempDir() + "pvb_run_" + std::to_string(::getpid()) + ".txt";
  const std::string inner = "trap '' XFSZ; ulimit -f " + std::to_string(max_kib) + "; exec " +
                            pvbench_path() + " " + args + " > " + log + " 2>&1";
  const int status = std::system(("bash -c \"" + inner + "\"").c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(log)};
}

/// Starts `pvbench ARGS...` as a child process, its stdout and stderr going
/// to log_path; returns the child's pid (-1 when fork fails).
inline pid_t spawn_pvbench(const std::vector<std::string>& args, const std::string& log_path) {
  const pid_t pid = fork();
  if (pid != 0) return pid;
  if (!std::freopen(log_path.c_str(), "w", stdout) || !std::freopen(log_path.c_str(), "a", stderr)) _exit(99);
  std::vector<char*> argv;
  static const std::string name = "pvbench";
  argv.push_back(const_cast<char*>(name.c_str()));
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  execv(pvbench_path().c_str(), argv.data());
  _exit(98);
}

/// Polls ready() every 50 ms for at most timeout_s.  False when the child
/// `pid` ended first or time ran out.
inline bool wait_until(pid_t pid, const std::function<bool()>& ready, double timeout_s) {
  const auto t0 = std::chrono::steady_clock::now();
  while (!ready()) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return false;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > timeout_s)
      return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return true;
}

/// Sends SIGINT (a Ctrl-C) to the child `pid` and waits at most timeout_s
/// for it to end.  Returns its wait status, or nullopt after killing it
/// with SIGKILL when it did not end in time.
inline std::optional<int> interrupt_and_wait(pid_t pid, double timeout_s) {
  if (kill(pid, SIGINT) != 0) return std::nullopt;
  const auto t0 = std::chrono::steady_clock::now();
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > timeout_s) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return std::nullopt;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return status;
}

}  // namespace pvb::test
