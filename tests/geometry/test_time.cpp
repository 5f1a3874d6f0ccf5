#include <gtest/gtest.h>

#include "pvb/geometry/time.hpp"

using namespace pvb::geom;

TEST(Time, FrameTimesAreExactMultiplesOfThePeriod) {
  // 30 Hz: frame 3 is exactly 0.1 s, frame 30000 exactly 1000 s (no drift).
  EXPECT_EQ(frame_time_ns(0, 3, 30.0), 100'000'000);
  EXPECT_EQ(frame_time_ns(0, 30000, 30.0), 1'000'000'000'000);
  EXPECT_EQ(frame_time_ns(5, 1, 30.0), 5 + 33'333'333);
}

TEST(Time, TumFormatHasMicroseconds) {
  EXPECT_EQ(format_tum_time(1'305'031'102'175'304'000), "1305031102.175304");
  EXPECT_EQ(format_tum_time(33'333'333), "0.033333");
  EXPECT_EQ(format_tum_time(0), "0.000000");
  EXPECT_EQ(seconds_to_ns(0.1), 100'000'000);
}
