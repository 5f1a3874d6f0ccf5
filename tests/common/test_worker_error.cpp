// A worker thread's exception reaches the thread that owns it, once,
// instead of ending the process with abort().
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <thread>

#include "pvb/common/worker_error.hpp"

TEST(WorkerError, AnExceptionOfAWorkerThreadIsRethrownByItsOwnerOnce) {
  pvb::WorkerError error;
  bool ran = false;
  std::thread worker([&] {
    ran = error.run([] { throw std::runtime_error("OpenCV(4.6.0) assertion failed"); });
  });
  worker.join();
  EXPECT_FALSE(ran);
  EXPECT_TRUE(error.failed());
  try {
    error.rethrow();
    ADD_FAILURE() << "nothing rethrown";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "OpenCV(4.6.0) assertion failed");
  }
  EXPECT_NO_THROW(error.rethrow());
}

TEST(WorkerError, AWorkerThatEndsWellHasNothingToRethrow) {
  pvb::WorkerError error;
  int n = 0;
  EXPECT_TRUE(error.run([&] { ++n; }));
  EXPECT_EQ(n, 1);
  EXPECT_FALSE(error.failed());
  EXPECT_NO_THROW(error.rethrow());
}
