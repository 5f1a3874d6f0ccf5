// A growing series kept to a bounded number of evenly spaced points, its
// last value always kept (unit).
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "pvb/report/thinned_series.hpp"

using pvb::run::ThinnedSeries;

TEST(ThinnedSeries, KeepsEveryRowUpToItsBound) {
  ThinnedSeries s(2, 10);
  for (int i = 0; i < 10; ++i) s.add({static_cast<double>(i), -static_cast<double>(i)});
  EXPECT_EQ(s.stride(), 1u);
  EXPECT_EQ(s.column(0), (std::vector<double>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(s.column(1).back(), -9.0);
}

TEST(ThinnedSeries, PastItsBoundKeepsEvenlySpacedRowsAndTheLast) {
  ThinnedSeries s(2, 64);
  for (int i = 0; i < 1000; ++i) s.add({static_cast<double>(i), 2.0 * i});
  EXPECT_EQ(s.rows_added(), 1000u);
  EXPECT_EQ(s.stride(), 16u);  // 1000 rows over at most 64 kept
  const std::vector<double> x = s.column(0), y = s.column(1);
  ASSERT_EQ(x.size(), y.size());
  ASSERT_LE(x.size(), 65u);
  EXPECT_EQ(x.front(), 0.0);
  EXPECT_EQ(x.back(), 999.0);  // the last row, kept although off the stride
  for (std::size_t i = 0; i + 1 < x.size(); ++i) {
    EXPECT_EQ(y[i], 2 * x[i]);  // the columns stay rows
    if (i + 2 < x.size()) {
      EXPECT_EQ(x[i + 1] - x[i], 16.0) << i;
    }
  }
}

TEST(ThinnedSeries, ALastRowOnTheStrideIsNotRepeated) {
  ThinnedSeries s(1, 4);
  for (int i = 0; i < 9; ++i)
    s.add({static_cast<double>(i)});  // stride 2 after the fifth row, 4 after the ninth
  EXPECT_EQ(s.column(0), (std::vector<double>{0, 4, 8}));
}

TEST(ThinnedSeries, RefusesWhatItCannotKeep) {
  EXPECT_THROW(ThinnedSeries(0, 10), std::invalid_argument);
  EXPECT_THROW(ThinnedSeries(2, 1), std::invalid_argument);
  ThinnedSeries s(2, 10);
  EXPECT_THROW(s.add({1.0}), std::invalid_argument);
}
