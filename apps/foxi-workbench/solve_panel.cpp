// foxi-workbench's results panel: the derived quantities and balance checks of the last solve.
#include "workbench.hpp"
#include "workbench_parts.hpp"

#include <QDockWidget>
#include <QHeaderView>
#include <QTableWidget>

namespace foxi::workbench {

void Workbench::build_results_panel() {
  // Results and history.
  results_table_ = new QTableWidget(0, 3);
  results_table_->setHorizontalHeaderLabels({tr("result"), tr("value"), tr("unit / check")});
  results_table_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  results_table_->setMinimumWidth(330);
  results_table_->verticalHeader()->hide();
  results_table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  auto* results_dock = new QDockWidget(tr("Results"));
  results_dock->setObjectName("results");
  results_dock->setWidget(results_table_);
  addDockWidget(Qt::RightDockWidgetArea, results_dock);
}

void Workbench::show_results() {
  const RunResults& r = results_;
  results_table_->setRowCount(0);
  auto add = [&](const QString& a, const QString& b, const QString& c) {
    const int row = results_table_->rowCount();
    results_table_->insertRow(row);
    results_table_->setItem(row, 0, new QTableWidgetItem(a));
    results_table_->setItem(row, 1, new QTableWidgetItem(b));
    results_table_->setItem(row, 2, new QTableWidgetItem(c));
  };
  add(tr("status"), run_status_name(r.status), QString::fromStdString(r.error));
  add(tr("nodes / tets"), QString("%1 / %2").arg(r.nodes).arg(r.tets), {});
  for (const ResultValue& v : r.values)
    add(QString::fromStdString(v.name) + (v.key ? " *" : ""), QString::number(v.value, 'g', 6),
        QString::fromStdString(v.unit));
  for (const BalanceCheck& c : r.checks)
    add(tr("check ") + QString::fromStdString(c.name), QString::number(c.figure, 'g', 3),
        (c.passed ? tr("ok, tolerance ") : tr("FAILED, tolerance ")) + QString::number(c.tolerance, 'g', 3));
}

}  // namespace foxi::workbench
