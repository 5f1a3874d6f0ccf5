// Thread names, per-thread CPU time and per-thread nice values (Linux).
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <future>
#include <thread>

#include "pvb/common/threads.hpp"

namespace {

/// A named worker that burns CPU until told to stop, then waits to be joined.
struct BusyWorker {
  std::atomic<bool> stop{false};
  std::promise<pid_t> tid;
  std::thread thread;
  explicit BusyWorker(const std::string& name) {
    thread = std::thread([this, name] {
      pvb::set_thread_name(name);
      tid.set_value(static_cast<pid_t>(syscall(SYS_gettid)));
      volatile double x = 0;
      while (!stop.load())
        for (int i = 0; i < 10000; ++i) x = x + 1e-9 * i;
    });
  }
  ~BusyWorker() {
    stop = true;
    thread.join();
  }
};

}  // namespace

TEST(Threads, CpuTimeIsReportedByNameWithTheNumberStripped) {
  BusyWorker a("pvbtest-1"), b("pvbtest-2");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto cpu = pvb::thread_cpu_ms();
  ASSERT_TRUE(cpu.count("pvbtest")) << "threads seen: " << cpu.size();
  EXPECT_GT(cpu.at("pvbtest"), 20.0);  // two busy threads over 300 ms
  EXPECT_FALSE(cpu.count("pvbtest-1"));
}

TEST(Threads, NiceIsSetOnTheNamedThreadOnly) {
  BusyWorker w("pvbtest-nice");
  const pid_t tid = w.tid.get_future().get();
  const pid_t self = static_cast<pid_t>(syscall(SYS_gettid));
  const int before = getpriority(PRIO_PROCESS, static_cast<id_t>(self));
  const int lower = std::min(19, before + 3);  // raising the value needs no privilege
  ASSERT_NE(lower, before) << "the test runs at nice 19 already";
  EXPECT_EQ(pvb::set_thread_nice("pvbtest-nice", lower), 1);
  EXPECT_EQ(getpriority(PRIO_PROCESS, static_cast<id_t>(tid)), lower);
  EXPECT_EQ(getpriority(PRIO_PROCESS, static_cast<id_t>(self)), before);  // the caller keeps its own
  EXPECT_EQ(pvb::set_thread_nice("no-such-thread", lower), 0);
}
