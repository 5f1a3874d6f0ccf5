#pragma once
// A figure's series that grow with a run (a reading every few milliseconds
// for an hour's drive), kept to a bounded number of points.
#include <cstddef>
#include <initializer_list>
#include <vector>

namespace pvb::run {

/// Rows of a fixed number of columns, appended one at a time, of which at
/// most `max_rows` are kept.  When one more would be kept, every other kept
/// row is dropped and from then on only every other row is kept (the
/// stride doubles), so the rows kept stay evenly spaced over the whole run:
/// a run of up to `max_rows` rows keeps them all.  `column` always ends
/// with the last row added, so a series' final value stays exact.
class ThinnedSeries {
 public:
  /// Throws std::invalid_argument when columns is 0 or max_rows under 2.
  ThinnedSeries(std::size_t columns, std::size_t max_rows);
  /// One row: as many values as columns (std::invalid_argument otherwise).
  void add(std::initializer_list<double> row);
  /// Column c's kept values, then the last row's when it was not kept.
  std::vector<double> column(std::size_t c) const;
  std::size_t rows_added() const { return added_; }
  std::size_t stride() const { return stride_; }  ///< rows added per row kept

 private:
  void halve();
  std::vector<std::vector<double>> kept_;
  std::vector<double> last_;
  std::size_t max_rows_, stride_ = 1, added_ = 0;
};

}  // namespace pvb::run
