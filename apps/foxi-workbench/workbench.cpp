// foxi-workbench's main window: see workbench.hpp; its panels are in their own files (workbench_parts.hpp).
#include "workbench.hpp"
#include "workbench_parts.hpp"

#include <QDockWidget>
#include <QKeySequence>
#include <QLabel>
#include <QMessageBox>
#include <QProgressBar>
#include <QPushButton>
#include <QSettings>
#include <QShortcut>
#include <QSlider>
#include <QStatusBar>
#include <QTimer>
#include <cmath>

namespace foxi::workbench {

Workbench::Workbench(QWidget* parent) : QMainWindow(parent) {
  build_ui();
  // Autosave: 2 s after the first change since the last one (a burst of edits is one save), on a
  // worker: a crash loses at most the last few seconds.
  autosave_timer_ = new QTimer(this);
  autosave_timer_->setSingleShot(true);
  autosave_timer_->setInterval(2000);
  connect(autosave_timer_, &QTimer::timeout, this, &Workbench::autosave);
  connect(view_, &foxi::qt::ViewWidget::draw_finished, this, &Workbench::changed);  // the camera moved
  poll_ = new QTimer(this);
  poll_->setInterval(100);
  connect(poll_, &QTimer::timeout, this, [this] {
    if (!job_) return;
    const int v = job_->permille->load();
    progress_->setValue(v % 10000);
    progress_->setFormat(progress_format(job_->what, v, job_->solve.get()));
  });
}

Workbench::~Workbench() {
  wait_autosave();
  if (job_) {
    job_->cancel->store(true);
    job_->watcher.waitForFinished();
  }
}

void Workbench::build_ui() {
  setWindowTitle("foxi workbench");
  QPushButton* save = build_view_panel();
  QPushButton* open = build_model_panel();
  build_mesh_panel();
  build_results_panel();
  build_history_panel();
  // The right side's two docks take the window's whole height (the history below the view and the
  // model panel only) and share it half and half: the mesh panel's settings in sight (its report
  // scrolls), the results table about 8 rows at the default 860 px (it had one: the mesh panel's
  // natural height took the side).
  setCorner(Qt::BottomRightCorner, Qt::RightDockWidgetArea);
  auto* mesh_dock = findChild<QDockWidget*>("mesh");
  auto* results_dock = findChild<QDockWidget*>("results");
  if (mesh_dock && results_dock) resizeDocks({mesh_dock, results_dock}, {1, 1}, Qt::Vertical);

  status_ = new QLabel;
  probe_ = new QLabel;
  statusBar()->addWidget(status_, 1);
  statusBar()->addPermanentWidget(probe_);
  connect(view_, &foxi::qt::ViewWidget::status_changed, status_, &QLabel::setText);
  connect(view_, &foxi::qt::ViewWidget::probe_changed, probe_, &QLabel::setText);
  connect(view_, &foxi::qt::ViewWidget::fraction_changed, this, [this](double f) {
    if (!fraction_->isSliderDown()) fraction_->setValue(int(std::lround(f * 1000)));
  });
  // Keyboard: the viewer's keys (foxi-view's), and the loop's; F1 lists them.
  auto keys = std::make_shared<QStringList>();
  auto key = [this, keys](const QKeySequence& k, const QString& what, auto fn) {
    connect(new QShortcut(k, this), &QShortcut::activated, this, fn);
    keys->append(k.toString(QKeySequence::NativeText) + "\t" + what);
  };
  key(QKeySequence("D"), tr("draw"), [this] { view_->draw(); });
  key(QKeySequence("Space"), tr("stop / go on"), [this] { view_->busy() ? view_->stop() : view_->resume(); });
  key(QKeySequence("N"), tr("step"), [this] { view_->step_once(); });
  key(QKeySequence("U"), tr("undraw"), [this] { view_->undraw(); });
  key(QKeySequence("R"), tr("region of interest"), [this] {
    QString why;
    if (!view_->push_region(&why)) param_error_->setText(why);
  });
  key(QKeySequence("B"), tr("back out of the region"), [this] { view_->pop_region(); });
  key(QKeySequence::Open, tr("open a model"), [open] { open->click(); });
  key(QKeySequence("Ctrl+M"), tr("mesh"), [this] { start_mesh(); });
  key(QKeySequence("Ctrl+R"), tr("solve"), [this] { start_solve(); });
  key(QKeySequence("Escape"), tr("cancel the running job"), [this] { cancel(); });
  key(QKeySequence::Save, tr("save the picture"), [save] { save->click(); });
  key(QKeySequence("Ctrl+Shift+S"), tr("save the model file"), [this] { save_model_file(); });
  key(QKeySequence::Undo, tr("undo a parameter edit"), [this] { undo(); });
  key(QKeySequence::Redo, tr("redo a parameter edit"), [this] { redo(); });
  key(QKeySequence::HelpContents, tr("these keys"),
      [this, keys] { QMessageBox::information(this, tr("Keyboard shortcuts"), keys->join("\n")); });
  statusBar()->addPermanentWidget(new QLabel(tr("F1: keys")));
  // The panels' natural widths side by side (the view's control rows unscrolled); a narrower screen
  // gets a narrower window, the control rows scrolled sideways (ControlRows, view_panel.cpp).
  resize(1680, 860);
}

void Workbench::restore_settings() {
  QSettings settings;
  restoreGeometry(settings.value("geometry").toByteArray());
  restoreState(settings.value("window_state").toByteArray());
}

void Workbench::closeEvent(QCloseEvent* event) {
  QSettings settings;
  settings.setValue("geometry", saveGeometry());
  settings.setValue("window_state", saveState());
  QMainWindow::closeEvent(event);
}

void Workbench::show_error(const QString& text) {
  last_error_ = text;
  param_error_->setText(text);
}

}  // namespace foxi::workbench
