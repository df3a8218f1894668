// foxi-workbench's run history: one row per model state meshed (and solved).
#include "workbench.hpp"
#include "history_plot.hpp"
#include "workbench_parts.hpp"

#include <QComboBox>
#include <QDialog>
#include <QDialogButtonBox>
#include <QDockWidget>
#include <QFormLayout>
#include <QLineEdit>
#include <QHBoxLayout>
#include <QPushButton>
#include <QVBoxLayout>
#include <QHeaderView>
#include <QTableWidget>
#include <cmath>

#include "foxi/model/sweep_values.hpp"

namespace foxi::workbench {

void Workbench::build_history_panel() {
  history_table_ = new QTableWidget(0, 5);
  history_table_->setObjectName("history_table");
  history_table_->setHorizontalHeaderLabels(
      {tr("run"), tr("parameters"), tr("tets"), tr("key results"), tr("time")});
  history_table_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  history_table_->horizontalHeader()->setSectionResizeMode(3, QHeaderView::Stretch);
  history_table_->verticalHeader()->hide();
  history_table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  auto* history_dock = new QDockWidget(tr("Run history"));
  history_dock->setObjectName("history");
  auto* panel = new QWidget;
  auto* v = new QVBoxLayout(panel);
  v->setContentsMargins(0, 0, 0, 0);
  v->addWidget(history_table_, 1);
  auto* plot = new QPushButton(tr("Plot a result against a parameter..."));
  plot->setObjectName("history_plot");
  connect(plot, &QPushButton::clicked, this,
          [this] { show_history_plot(this, model_path_, history_, si_units_); });
  auto* sweep = new QPushButton(tr("Sweep a parameter..."));
  sweep->setObjectName("history_sweep");
  sweep->setToolTip(tr("each value meshed and solved, one row each (foxi sweep --vary)"));
  connect(sweep, &QPushButton::clicked, this, &Workbench::run_sweep_dialog);
  auto* buttons = new QHBoxLayout;
  buttons->addWidget(plot);
  buttons->addWidget(sweep);
  buttons->addStretch(1);
  v->addLayout(buttons);
  history_dock->setWidget(panel);
  addDockWidget(Qt::BottomDockWidgetArea, history_dock);
}

void Workbench::run_sweep_dialog() {
  if (!model_) return;
  QDialog dialog(this);
  dialog.setWindowTitle(tr("Sweep a parameter"));
  auto* form = new QFormLayout(&dialog);
  auto* name = new QComboBox;
  for (const Parameter& p : model_->parameters) name->addItem(QString::fromStdString(p.name));
  auto* values = new QLineEdit;
  values->setPlaceholderText(tr("2mm:8mm:4 (from, to, count) or 2mm,3mm,5mm"));
  form->addRow(tr("parameter"), name);
  form->addRow(tr("values"), values);
  auto* box = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
  connect(box, &QDialogButtonBox::accepted, &dialog, &QDialog::accept);
  connect(box, &QDialogButtonBox::rejected, &dialog, &QDialog::reject);
  form->addRow(box);
  if (dialog.exec() != QDialog::Accepted) return;
  // foxi sweep --vary's two forms: LO:HI:N, or a list
  QStringList list;
  try {
    for (const std::string& t : parse_sweep_values(values->text().trimmed().toStdString()).texts)
      list << QString::fromStdString(t);
  } catch (const std::exception& e) {
    show_error(tr("sweep: %1").arg(what_of(e)));
    return;
  }
  start_sweep(name->currentText(), list);
}

void Workbench::add_history(double seconds) {
  HistoryRow row;
  row.parameters = meshed_overrides_;
  row.mesh = mesh_serial_;
  row.tets = mesh_ ? mesh_->tet_count() : 0;
  if (has_results_)
    row.results = results_;
  else
    row.results.status = RunStatus::failed, row.results.error = "meshed only";
  row.seconds = seconds;
  row.mesh_settings = meshed_settings_;
  // A solve of the mesh the last row made completes that row (one row per model state).
  // (a sweep's rows have mesh 0: no mesh of theirs is kept)
  const bool complete = has_results_ && !history_.empty() && history_.back().results.values.empty() &&
                        history_.back().mesh == row.mesh && row.mesh != 0;
  int i = history_table_->rowCount();
  if (complete) {
    history_.back() = row;
    --i;
  } else {
    history_.push_back(row);
    history_table_->insertRow(i);
  }
  fill_history_row(i, row);
}

void Workbench::fill_history_row(int i, const HistoryRow& row) {
  QString params;
  for (const ParameterOverride& o : row.parameters)
    params += QString::fromStdString(o.name + "=" + o.expression + " ");
  QString key;
  for (const ResultValue& v : row.results.values)
    if (v.key) {
      const DisplayUnit u = shown_unit(v.unit, std::abs(v.value));  // the results table's unit
      key += QString("%1 %2 %3; ")
                 .arg(QString::fromStdString(v.name))
                 .arg(u.to_display(v.value), 0, 'g', 5)
                 .arg(QString::fromStdString(u.symbol));
    }
  if (row.results.values.empty() && !row.results.error.empty() && row.results.error != "meshed only")
    key = tr("FAILED: %1").arg(QString::fromStdString(row.results.error));
  history_table_->setItem(i, 0, new QTableWidgetItem(QString::number(i + 1)));
  history_table_->setItem(i, 1, new QTableWidgetItem(params.isEmpty() ? tr("(as in the file)") : params));
  history_table_->setItem(i, 2, new QTableWidgetItem(QString::number(row.tets)));
  history_table_->setItem(i, 3, new QTableWidgetItem(key.isEmpty() ? tr("meshed only") : key));
  history_table_->setItem(i, 4, new QTableWidgetItem(QString("%1 s").arg(row.seconds, 0, 'f', 2)));
  // The mesh settings that made the row's mesh, on the whole row (hover any cell).
  const QString settings =
      row.mesh_settings ? mesh_settings_text(*row.mesh_settings, model_ ? model_->length_scale : 1,
                                             model_ ? model_->length_unit : "m")
                        : tr("mesh settings not recorded (a project saved before history rows kept them)");
  for (int c = 0; c < history_table_->columnCount(); ++c) history_table_->item(i, c)->setToolTip(settings);
}

void Workbench::refresh_history() {
  history_table_->setRowCount(int(history_.size()));
  for (std::size_t i = 0; i < history_.size(); ++i) fill_history_row(int(i), history_[i]);
}

}  // namespace foxi::workbench
