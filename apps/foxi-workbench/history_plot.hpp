// foxi-workbench's history plot: a result of the run history against a parameter, drawn by the
// chart drawing of foxi/viz/chart.hpp (the one foxi's transient charts use; no QtCharts).
#pragma once

#include <QImage>
#include <QString>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "workbench.hpp"

namespace foxi::workbench {

// The points of `result` (a RunResults value's name) against `parameter` over the history rows that
// have both: x the parameter's value (SI) as the model file `model` evaluates it with the row's
// overrides, y the result's value, in row order.
struct HistoryPoints {
  std::vector<double> x, y;
  std::vector<std::size_t> rows;  // the history rows plotted
  std::string x_unit, y_unit;     // SI dimensions of the parameter; the result's unit
};
HistoryPoints history_points(const std::filesystem::path& model, std::span<const HistoryRow> rows,
                             const std::string& parameter, const std::string& result);

// The names of the results the rows have (in order of first appearance).
std::vector<std::string> history_results(std::span<const HistoryRow> rows);

// The chart of the points (markers joined in x order), width x height; a null image when there are
// no points. `report` (when given) receives the chart's pixel places of the points.
QImage history_chart(const HistoryPoints& points, const std::string& parameter, const std::string& result,
                     int width, int height, std::vector<std::pair<int, int>>* pixels = nullptr);

// A window beside `parent` with a parameter and a result to choose and their chart, for the history
// `rows` of the model file `model` (whose parameters the choice lists); the result in SI units
// (`si_units`) or the engineer's (°C, MPa, ...), as the results table shows it.
void show_history_plot(QWidget* parent, const QString& model, std::vector<HistoryRow> rows, bool si_units);

}  // namespace foxi::workbench
