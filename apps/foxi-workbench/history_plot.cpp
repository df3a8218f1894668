// foxi-workbench's history plot (history_plot.hpp).
#include "history_plot.hpp"

#include <QComboBox>
#include <QDialog>
#include <QHBoxLayout>
#include <QLabel>
#include <QPixmap>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "foxi/model/units.hpp"
#include "foxi/viz/chart.hpp"
#include "foxi/viz/text.hpp"
#include "workbench_parts.hpp"

namespace foxi::workbench {

HistoryPoints history_points(const std::filesystem::path& model, std::span<const HistoryRow> rows,
                             const std::string& parameter, const std::string& result) {
  HistoryPoints out;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto value = std::find_if(rows[i].results.values.begin(), rows[i].results.values.end(),
                                    [&](const ResultValue& v) { return v.name == result; });
    if (value == rows[i].results.values.end()) continue;
    // the parameter as the model evaluates it with that run's overrides (an expression of others too)
    const Model m = load_model(model, rows[i].parameters, "the run history");
    for (const Parameter& p : m.parameters)
      if (p.name == parameter) {
        out.x.push_back(p.value.value);
        out.y.push_back(value->value);
        out.rows.push_back(i);
        out.x_unit = dims_to_string(p.value.dims);
        out.y_unit = value->unit;
      }
  }
  return out;
}

std::vector<std::string> history_results(std::span<const HistoryRow> rows) {
  std::vector<std::string> out;
  for (const HistoryRow& r : rows)
    for (const ResultValue& v : r.results.values)
      if (std::find(out.begin(), out.end(), v.name) == out.end()) out.push_back(v.name);
  return out;
}

QImage history_chart(const HistoryPoints& points, const std::string& parameter, const std::string& result,
                     int width, int height, std::vector<std::pair<int, int>>* pixels) {
  if (points.x.empty()) return {};
  // joined in x order (the runs were made in any order)
  std::vector<std::size_t> order(points.x.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return points.x[a] < points.x[b]; });
  Chart chart;
  chart.title = result + " against " + parameter;
  chart.x.label = parameter;
  chart.x.unit = points.x_unit;
  chart.y.label = result;
  chart.y.unit = points.y_unit;
  ChartSeries s;
  for (std::size_t i : order) {
    s.x.push_back(points.x[i]);
    s.y.push_back(points.y[i]);
  }
  s.markers = true;
  chart.series.push_back(std::move(s));
  Framebuffer fb(width, height);
  const TextRenderer text(find_font_file());
  const ChartReport report = draw_chart(fb, text, chart, PixelRect{0, 0, width - 1, height - 1});
  if (pixels && !report.points.empty()) {
    pixels->assign(points.x.size(), {0, 0});
    for (std::size_t k = 0; k < order.size(); ++k) (*pixels)[order[k]] = report.points[0][k];
  }
  return QImage(reinterpret_cast<const uchar*>(fb.rgba.data()), fb.width, fb.height, fb.width * 4,
                QImage::Format_RGBA8888)
      .copy();
}

void show_history_plot(QWidget* parent, const QString& model, std::vector<HistoryRow> rows, bool si_units) {
  auto* dialog = new QDialog(parent);
  dialog->setAttribute(Qt::WA_DeleteOnClose);
  dialog->setWindowTitle(QObject::tr("Run history: a result against a parameter"));
  auto* parameter = new QComboBox;
  auto* result = new QComboBox;
  try {
    for (const Parameter& p :
         load_model(model.toStdString(), std::span<const ParameterOverride>{}).parameters)
      parameter->addItem(QString::fromStdString(p.name));
  } catch (const std::exception&) {  // the model no longer loads: nothing to choose
  }
  for (const std::string& r : history_results(rows)) result->addItem(QString::fromStdString(r));
  auto* chart = new QLabel;
  chart->setMinimumSize(480, 320);
  auto* why = new QLabel;
  auto* row = new QHBoxLayout;
  row->addWidget(result);
  row->addWidget(new QLabel(QObject::tr("against")));
  row->addWidget(parameter);
  auto* v = new QVBoxLayout(dialog);
  v->addLayout(row);
  v->addWidget(chart, 1);
  v->addWidget(why);
  auto redraw = [=, rows = std::move(rows)] {
    try {
      const std::string p = parameter->currentText().toStdString(), r = result->currentText().toStdString();
      HistoryPoints points = history_points(model.toStdString(), rows, p, r);
      // the result in the unit the results table and the legend show it in (°C, MPa, ... or SI)
      double most = 0;
      for (double y : points.y) most = std::max(most, std::abs(y));
      const DisplayUnit unit = unit_for(points.y_unit, most, si_units);
      for (double& y : points.y) y = unit.to_display(y);
      points.y_unit = unit.symbol;
      const qreal ratio = chart->devicePixelRatioF();
      QImage image = history_chart(points, p, r, int(480 * ratio), int(320 * ratio));
      why->setText(image.isNull() ? QObject::tr("no run has both") : QString());
      QPixmap pixmap = QPixmap::fromImage(image);
      pixmap.setDevicePixelRatio(ratio);
      chart->setPixmap(pixmap);
    } catch (const std::exception& e) {
      why->setText(QString::fromStdString(e.what()));
    }
  };
  QObject::connect(parameter, &QComboBox::currentTextChanged, dialog, redraw);
  QObject::connect(result, &QComboBox::currentTextChanged, dialog, redraw);
  redraw();
  dialog->show();
}

}  // namespace foxi::workbench
