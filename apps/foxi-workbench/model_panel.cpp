// foxi-workbench's model panel: the model file, its parameter table (undo, redo), parts and conditions.
#include "workbench.hpp"
#include "workbench_parts.hpp"

#include <QDockWidget>
#include <QFileDialog>
#include <QFileInfo>
#include <QHeaderView>
#include <QLabel>
#include <QPlainTextEdit>
#include <QProgressBar>
#include <QPushButton>
#include <QSettings>
#include <QTableWidget>
#include <QTimer>
#include <QVBoxLayout>

#include "foxi/model/units.hpp"

namespace foxi::workbench {

QPushButton* Workbench::build_model_panel() {
  // The model panel: open, parameters (editable), the model's parts and conditions.
  auto* left = new QWidget;
  auto* lv = new QVBoxLayout(left);
  auto* open = new QPushButton(tr("Open model..."));
  connect(open, &QPushButton::clicked, this, [this] {
    QSettings settings;
    const QString f = QFileDialog::getOpenFileName(
        this, tr("Open a model"), settings.value("last_model").toString(), tr("Models (*.toml)"));
    if (!f.isEmpty() && open_model(f)) settings.setValue("last_model", f);
  });
  lv->addWidget(open);
  lv->addLayout(build_model_file_row());
  lv->addLayout(build_project_row());
  params_ = new QTableWidget(0, 3);
  params_->setObjectName("parameters");
  params_->setHorizontalHeaderLabels({tr("parameter"), tr("expression"), tr("value (SI)")});
  params_->horizontalHeader()->setStretchLastSection(true);
  params_->verticalHeader()->hide();
  connect(params_, &QTableWidget::cellChanged, this, &Workbench::on_parameter_edited);
  lv->addWidget(params_, 2);
  param_error_ = new QLabel;
  param_error_->setObjectName("parameter_error");
  param_error_->setWordWrap(true);
  param_error_->setStyleSheet("color: #b00000");
  lv->addWidget(param_error_);
  model_text_ = new QPlainTextEdit;
  model_text_->setReadOnly(true);
  lv->addWidget(model_text_, 1);
  lv->addWidget(build_parts_picture(), 1);
  auto* jobs = new QHBoxLayout;
  mesh_button_ = new QPushButton(tr("Mesh"));
  solve_button_ = new QPushButton(tr("Solve (thermal)"));
  cancel_button_ = new QPushButton(tr("Cancel"));
  cancel_button_->setEnabled(false);
  connect(mesh_button_, &QPushButton::clicked, this, [this] { start_mesh(); });
  connect(solve_button_, &QPushButton::clicked, this, [this] { start_solve(); });
  connect(cancel_button_, &QPushButton::clicked, this, &Workbench::cancel);
  jobs->addWidget(mesh_button_);
  jobs->addWidget(solve_button_);
  jobs->addWidget(cancel_button_);
  lv->addLayout(jobs);
  progress_ = new QProgressBar;
  progress_->setRange(0, 1000);
  progress_->setValue(0);
  lv->addWidget(progress_);
  auto* model_dock = new QDockWidget(tr("Model"));
  model_dock->setObjectName("model");
  model_dock->setWidget(left);
  addDockWidget(Qt::LeftDockWidgetArea, model_dock);
  return open;
}

bool Workbench::open_model(const QString& path, QString* error) {
  try {
    auto m =
        std::make_shared<const Model>(load_model(path.toStdString(), std::span<const ParameterOverride>{}));
    model_path_ = path;
    overrides_.clear();
    model_ = std::move(m);
    undo_.clear();
    redo_.clear();
    show_error({});
    setWindowTitle("foxi workbench - " + QFileInfo(path).fileName());
    refresh_model_panel();
    return true;
  } catch (const std::exception& e) {
    show_error(what_of(e));
    if (error) *error = what_of(e);
    return false;
  }
}

std::vector<ParameterOverride> Workbench::overrides() const {
  std::vector<ParameterOverride> out;
  for (const auto& [n, e] : overrides_) out.push_back({n, e});
  return out;
}

bool Workbench::set_parameter(const QString& name, const QString& expression, QString* error) {
  if (model_path_.isEmpty()) {
    if (error) *error = tr("open a model first");
    return false;
  }
  auto trial = overrides_;
  trial[name.toStdString()] = expression.toStdString();
  const auto before = overrides_;
  if (!apply_overrides(std::move(trial), error)) return false;
  undo_.push_back(before);
  redo_.clear();
  return true;
}

bool Workbench::apply_overrides(std::map<std::string, std::string> trial, QString* error) {
  std::vector<ParameterOverride> list;
  for (const auto& [n, e] : trial) list.push_back({n, e});
  try {
    // The model library's own check: units, expressions, geometry limits (a model file load).
    auto m =
        std::make_shared<const Model>(load_model(model_path_.toStdString(), list, "the parameter table"));
    overrides_ = std::move(trial);
    model_ = std::move(m);
    changed();
    show_error({});
    refresh_model_panel();
    return true;
  } catch (const std::exception& e) {
    show_error(what_of(e));
    if (error) *error = what_of(e);
    refresh_model_panel();  // the cell shows the accepted expression again
    return false;
  }
}

bool Workbench::undo() {
  if (undo_.empty()) return false;
  const auto now = overrides_;
  if (!apply_overrides(undo_.back(), nullptr)) return false;  // the model file changed meanwhile
  undo_.pop_back();
  redo_.push_back(now);
  return true;
}

bool Workbench::redo() {
  if (redo_.empty()) return false;
  const auto now = overrides_;
  if (!apply_overrides(redo_.back(), nullptr)) return false;
  redo_.pop_back();
  undo_.push_back(now);
  return true;
}

void Workbench::on_parameter_edited(int row, int column) {
  if (filling_ || column != 1) return;
  const QString name = params_->item(row, 0)->text(), expr = params_->item(row, 1)->text();
  // After the table's signal returns: the check refills the table, which deletes this cell's item.
  QTimer::singleShot(0, this, [this, row, name, expr] {
    QString error;
    if (!set_parameter(name, expr, &error)) {
      // The message next to the field at fault: the row is marked and the message shown under it.
      params_->selectRow(row);
      param_error_->setText(tr("%1: %2").arg(name, error));
    }
  });
}

void Workbench::refresh_model_panel() {
  filling_ = true;
  params_->setRowCount(0);
  if (model_) {
    params_->setRowCount(int(model_->parameters.size()));
    int row = 0;
    for (const Parameter& p : model_->parameters) {
      auto* n = new QTableWidgetItem(QString::fromStdString(p.name));
      n->setFlags(n->flags() & ~Qt::ItemIsEditable);
      auto* v = new QTableWidgetItem(QString("%1 %2")
                                         .arg(p.value.value, 0, 'g', 6)
                                         .arg(QString::fromStdString(dims_to_string(p.value.dims))));
      v->setFlags(v->flags() & ~Qt::ItemIsEditable);
      auto* e = new QTableWidgetItem(QString::fromStdString(p.expression));
      if (p.overridden) e->setBackground(QColor(255, 245, 200));
      params_->setItem(row, 0, n);
      params_->setItem(row, 1, e);
      params_->setItem(row, 2, v);
      ++row;
    }
    QString text;
    text += tr("length unit %1\n").arg(QString::fromStdString(model_->length_unit));
    for (const Part& p : model_->parts)
      text += tr("part %1: %2, %3 (line %4)\n")
                  .arg(QString::fromStdString(p.name), QString::fromStdString(p.shape),
                       QString::fromStdString(p.material))
                  .arg(p.line);
    text += tr("%1 materials, %2 conditions, %3 loads\n")
                .arg(model_->materials.size())
                .arg(model_->conditions.size())
                .arg(model_->loads.size());
    model_text_->setPlainText(text);
  }
  filling_ = false;
  refresh_parts_picture();
  refresh_mesh_controls();  // the parts' sizes (mesh_panel.cpp)
}

}  // namespace foxi::workbench
