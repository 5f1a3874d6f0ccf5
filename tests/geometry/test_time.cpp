#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>

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

// Any int64 formats without overflow (rounding to microseconds used to add
// 500 ns first), and seconds from outside are checked before conversion.
TEST(Time, ExtremeTimesFormatAndCheck) {
  EXPECT_EQ(format_tum_time(std::numeric_limits<std::int64_t>::max()), "9223372036.854776");
  EXPECT_EQ(format_tum_time(std::numeric_limits<std::int64_t>::min()), "-9223372036.854776");
  EXPECT_EQ(format_tum_time(-1'500), "-0.000002");
  EXPECT_EQ(format_tum_time(1'499), "0.000001");
  EXPECT_EQ(checked_seconds_to_ns(1.5), std::optional<std::int64_t>(1'500'000'000));
  EXPECT_EQ(checked_seconds_to_ns(-9e9), std::optional<std::int64_t>(-9'000'000'000'000'000'000));
  for (const double bad : {std::nan(""), HUGE_VAL, -HUGE_VAL, 9.3e9, -1e300})
    EXPECT_FALSE(checked_seconds_to_ns(bad).has_value()) << bad;
  EXPECT_EQ(saturating_add_ns(std::numeric_limits<std::int64_t>::max() - 1, 5),
            std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(saturating_add_ns(std::numeric_limits<std::int64_t>::min() + 1, -5),
            std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(saturating_add_ns(-5, 7), 2);
  EXPECT_FALSE(checked_add_ns(std::numeric_limits<std::int64_t>::max(), 1).has_value());
  EXPECT_EQ(checked_add_ns(-5, 7), std::optional<std::int64_t>(2));
}
