#pragma once
// A matrix figure: rows x columns of cells coloured by a share in [0, 1]
// (red 0, yellow 0.5, green 1) with the value written in each; cells with
// no value stay grey.  Campaigns draw map session x query session with it.
#include <optional>
#include <string>
#include <vector>

namespace pvb::plot {

struct MatrixFigure {
  std::string title;
  std::string row_label, col_label;  ///< axis titles
  std::vector<std::string> rows, cols;
  /// values[r][c] in [0, 1], or nullopt for a cell that was not measured.
  std::vector<std::vector<std::optional<double>>> values;
};

/// Writes the figure as PATH_BASE.svg and PATH_BASE.png.  Throws IoError.
void write_matrix(const MatrixFigure& m, const std::string& path_base);

}  // namespace pvb::plot
