// foxi-workbench's main window: see workbench.hpp; its panels are in their own files (workbench_parts.hpp).
#include "workbench.hpp"
#include "workbench_parts.hpp"

#include <QKeySequence>
#include <QLabel>
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
    const char* stage = progress_stage(v / 10000);
    progress_->setFormat(job_->what + (*stage ? QString(" (%1)").arg(stage) : QString()) + " %p%");
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

  status_ = new QLabel;
  probe_ = new QLabel;
  statusBar()->addWidget(status_, 1);
  statusBar()->addPermanentWidget(probe_);
  connect(view_, &foxi::qt::ViewWidget::status_changed, status_, &QLabel::setText);
  connect(view_, &foxi::qt::ViewWidget::probe_changed, probe_, &QLabel::setText);
  connect(view_, &foxi::qt::ViewWidget::fraction_changed, this, [this](double f) {
    if (!fraction_->isSliderDown()) fraction_->setValue(int(std::lround(f * 1000)));
  });
  // Keyboard: the viewer's keys (foxi-view's), and the loop's.
  auto key = [this](const QKeySequence& k, auto fn) {
    connect(new QShortcut(k, this), &QShortcut::activated, this, fn);
  };
  key(QKeySequence("D"), [this] { view_->draw(); });
  key(QKeySequence("Space"), [this] { view_->busy() ? view_->stop() : view_->resume(); });
  key(QKeySequence("N"), [this] { view_->step_once(); });
  key(QKeySequence("U"), [this] { view_->undraw(); });
  key(QKeySequence("R"), [this] { view_->push_region(); });
  key(QKeySequence("B"), [this] { view_->pop_region(); });
  key(QKeySequence::Open, [open] { open->click(); });
  key(QKeySequence("Ctrl+M"), [this] { start_mesh(); });
  key(QKeySequence("Ctrl+R"), [this] { start_solve(); });
  key(QKeySequence("Escape"), [this] { cancel(); });
  key(QKeySequence::Save, [save] { save->click(); });
  key(QKeySequence("Ctrl+Shift+S"), [this] { save_model_file(); });
  key(QKeySequence::Undo, [this] { undo(); });
  key(QKeySequence::Redo, [this] { redo(); });
  resize(1280, 860);
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
