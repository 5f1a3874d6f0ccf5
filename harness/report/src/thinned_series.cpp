#include "pvb/report/thinned_series.hpp"

#include <stdexcept>

namespace pvb::run {

ThinnedSeries::ThinnedSeries(std::size_t columns, std::size_t max_rows)
    : kept_(columns), last_(columns, 0.0), max_rows_(max_rows) {
  if (columns == 0) throw std::invalid_argument("ThinnedSeries: no columns");
  if (max_rows < 2) throw std::invalid_argument("ThinnedSeries: max_rows must be at least 2");
}

void ThinnedSeries::add(std::initializer_list<double> row) {
  if (row.size() != kept_.size())
    throw std::invalid_argument("ThinnedSeries: a row needs one value a column");
  last_.assign(row.begin(), row.end());
  const std::size_t index = added_++;
  if (index % stride_ != 0) return;
  for (std::size_t c = 0; c < kept_.size(); ++c) kept_[c].push_back(last_[c]);
  if (kept_.front().size() > max_rows_) halve();
}

/// Keeps the rows at even positions: those whose index is a multiple of
/// the doubled stride.
void ThinnedSeries::halve() {
  for (std::vector<double>& col : kept_) {
    std::size_t out = 0;
    for (std::size_t i = 0; i < col.size(); i += 2) col[out++] = col[i];
    col.resize(out);
  }
  stride_ *= 2;
}

std::vector<double> ThinnedSeries::column(std::size_t c) const {
  std::vector<double> out = kept_.at(c);
  if (added_ > 0 && (added_ - 1) % stride_ != 0) out.push_back(last_[c]);
  return out;
}

}  // namespace pvb::run
