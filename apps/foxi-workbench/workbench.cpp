// foxi-workbench's main window: see workbench.hpp.
#include "workbench.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDir>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QFutureWatcher>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QImage>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QLabel>
#include <QListWidget>
#include <QMenu>
#include <QPainter>
#include <QPlainTextEdit>
#include <QProgressBar>
#include <QPushButton>
#include <QSettings>
#include <QShortcut>
#include <QSignalBlocker>
#include <QSlider>
#include <QSplitter>
#include <QStatusBar>
#include <QTableWidget>
#include <QTimer>
#include <QToolBar>
#include <QVBoxLayout>
#include <QtConcurrent/QtConcurrentRun>
#include <chrono>
#include <cmath>
#include <exception>
#include <initializer_list>
#include <iterator>
#include <tuple>

#include "foxi/mesher/mesher.hpp"
#include "foxi/mesher/model_mesh.hpp"
#include "foxi/mesher/quality_report.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/model/progress.hpp"
#include "foxi/model/units.hpp"
#include "foxi/solver/model_problem.hpp"
#include "foxi/solver/thermal.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/colormap.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/interactive_view.hpp"
#include "foxi/viz/legend.hpp"
#include "foxi/viz/rasterizer.hpp"

namespace foxi::workbench {

struct Outcome {
  bool ok = false, cancelled = false;
  bool bad_input = false;  // the error is the model's (IoError: file, line, reason)
  QString error;
  bool meshed = false, solved = false;
  std::shared_ptr<const Mesh> mesh;
  std::shared_ptr<const Model> model;
  std::vector<ParameterOverride> overrides;
  std::unique_ptr<InteractiveView> view;
  std::vector<double> probe;  // per tet, display unit
  QString probe_unit, field_label;
  ColorScale scale;
  DisplayUnit unit;
  bool has_scale = false;
  std::vector<std::uint32_t> base;    // the tets of the regions shown (empty: all)
  std::optional<FieldChoice> choice;  // the field shown, for the field tools
  std::size_t step = 0;
  std::shared_ptr<IsoCache> iso_cache;  // built here, on the worker: the tools then only query
  double corner_lo = 0, corner_hi = 0;  // the corner values' range, SI
  RunResults results;
  double seconds = 0;                        // meshing (or the solve when not meshed)
  double solve_seconds = 0;                  // the solve
  std::optional<MeshQualityReport> quality;  // a new mesh's
};

struct Workbench::Job {
  std::shared_ptr<std::atomic<bool>> cancel;
  std::shared_ptr<std::atomic<int>> permille;
  QFutureWatcher<std::shared_ptr<Outcome>> watcher;
  QString what;
};

namespace {

using Clock = std::chrono::steady_clock;

// The stages the libraries report (progress.hpp's ProgressFn), numbered for the progress value the
// worker stores in one atomic: stage * 10000 + fraction in permille. 0: unknown.
const char* const kStages[] = {"", "meshing", "conforming refinement", "assemble", "factorize", "solve"};
int stage_index(std::string_view name) {
  for (int i = 1; i < int(std::size(kStages)); ++i)
    if (name == kStages[i]) return i;
  return 0;
}

const char* progress_stage(int index) {
  return index > 0 && index < int(std::size(kStages)) ? kStages[index] : "";
}

// The display of `mesh` on the worker: the field's paint, flat or graded, on the automatic scale or
// the user's range (as foxi render --field NAME --cmap MAP [--graded] [--range a,b] draws it) and the
// view, built with `camera` (null: the default).
void build_display(Outcome& out, const Mesh& mesh, const std::string& field, const Colouring& colouring,
                   double shrink, int w, int h, const Camera* camera) {
  // The regions shown: the tets of the others left out (foxi render --regions); the automatic colour
  // range is that of the tets shown, as there.
  if (!colouring.hidden.empty()) {
    for (std::size_t t = 0; t < mesh.tet_count(); ++t)
      if (std::find(colouring.hidden.begin(), colouring.hidden.end(), mesh.region_of(t)) ==
          colouring.hidden.end())
        out.base.push_back(std::uint32_t(t));
    if (out.base.empty()) throw std::runtime_error("every region is hidden: nothing to show");
  }
  RenderParams params;
  params.undoable = true;  // the workbench undraws
  params.shrink = shrink;
  if (!field.empty()) {
    const FieldChoice choice = choose_field(mesh, field);
    const std::size_t step = choice.field->step_count() - 1;
    const std::vector<double> values = tet_centroid_values(mesh, choice, step);
    out.iso_cache = std::make_shared<IsoCache>(make_iso_cache(mesh, choice, step));
    // The values drawn: per tet, or per tet corner (graded); the unit and automatic range are theirs.
    const std::vector<double>& all = colouring.graded ? *out.iso_cache->corner : values;
    std::vector<double> shown;
    const std::size_t per = colouring.graded ? 4 : 1;
    for (std::uint32_t t : out.base)
      shown.insert(shown.end(), all.begin() + std::ptrdiff_t(per * t),
                   all.begin() + std::ptrdiff_t(per * (t + 1)));
    const std::vector<double>& drawn = out.base.empty() ? all : shown;
    const ColorMapId map = parse_color_map(colouring.cmap).value_or(ColorMapId::viridis);
    const auto [lo, hi] = finite_range(drawn);
    out.unit = default_display_unit(choice.field->unit,
                                    std::isfinite(lo) ? std::max(std::abs(lo), std::abs(hi)) : 0);
    ColorScale scale;
    if (colouring.range) {
      scale.map = map;
      scale.lo = out.unit.to_si(colouring.range->first);
      scale.hi = out.unit.to_si(colouring.range->second);
      if (scale.lo > scale.hi) std::swap(scale.lo, scale.hi);
    } else {
      const std::optional<AutoScale> a = automatic_scale(drawn, map);
      if (!a) throw FieldSelectError("field '" + field + "' has no finite value");
      scale = a->scale;
    }
    params.field = std::make_shared<const FieldPaint>(colouring.graded ? graded_field_paint(all, scale)
                                                                       : flat_field_paint(all, scale));
    out.scale = scale;
    out.has_scale = true;
    out.probe.resize(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) out.probe[i] = out.unit.to_display(values[i]);
    out.probe_unit = QString::fromStdString(out.unit.symbol);
    out.field_label = QString::fromStdString(choice.label);
    out.choice = choice;
    out.step = step;
    std::tie(out.corner_lo, out.corner_hi) = finite_range(*out.iso_cache->corner);
  }
  out.view = foxi::qt::make_view(mesh, params, w, h, camera);
}

QString what_of(const std::exception& e) { return QString::fromStdString(e.what()); }

bool same_overrides(const std::vector<ParameterOverride>& a, const std::vector<ParameterOverride>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(),
                    [](const ParameterOverride& x, const ParameterOverride& y) {
                      return x.name == y.name && x.expression == y.expression;
                    });
}

// A colour bar with ticks (colormap.hpp's entries and nice_ticks), in the field's display unit.
QPixmap legend_pixmap(const ColorScale& s, const DisplayUnit& unit, const QString& label, int height) {
  const int w = 150, bar = 18, top = 24, bottom = 10, h = std::max(height, 120);
  QImage img(w, h, QImage::Format_RGB32);
  img.fill(Qt::white);
  QPainter p(&img);
  const int span = h - top - bottom;
  for (int y = 0; y < span; ++y) {
    const std::uint32_t c = s.color_at(1.0 - (y + 0.5) / span);
    p.setPen(QColor(int(c & 255), int(c >> 8 & 255), int(c >> 16 & 255)));
    p.drawLine(8, top + y, 8 + bar, top + y);
  }
  p.setPen(Qt::black);
  p.drawRect(8, top, bar, span);
  p.drawText(4, 16, label + " [" + QString::fromStdString(unit.symbol) + "]");
  const double lo = unit.to_display(s.lo), hi = unit.to_display(s.hi);
  const std::vector<double> ticks = nice_ticks(std::min(lo, hi), std::max(lo, hi), 6);
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1;
  for (double t : ticks) {
    const double pos = s.position(unit.to_si(t));
    const int y = top + int(std::lround((1 - pos) * span));
    p.drawLine(8 + bar, y, 8 + bar + 4, y);
    p.drawText(8 + bar + 8, y + 5, QString::fromStdString(tick_label(t, step)));
  }
  return QPixmap::fromImage(img);
}

// The minimum dihedral angle histogram of the quality report as a bar chart (5-degree bins).
QPixmap histogram_pixmap(const MeshQualityReport& q) {
  const int w = 300, h = 130, left = 8, bottom = 18, top = 16;
  QImage img(w, h, QImage::Format_RGB32);
  img.fill(Qt::white);
  QPainter p(&img);
  std::size_t most = 1;
  for (std::size_t c : q.min_dihedral_histogram) most = std::max(most, c);
  const int bins = int(q.min_dihedral_histogram.size()), bw = (w - 2 * left) / bins;
  for (int i = 0; i < bins; ++i) {
    const int bh = int(
        std::lround(double(q.min_dihedral_histogram[std::size_t(i)]) / double(most) * (h - top - bottom)));
    p.fillRect(left + i * bw + 1, h - bottom - bh, bw - 2, bh, QColor(70, 110, 170));
  }
  p.setPen(Qt::black);
  p.drawLine(left, h - bottom, left + bins * bw, h - bottom);
  for (int deg = 0; deg <= 75; deg += 15) p.drawText(left + deg / 5 * bw - 6, h - 3, QString::number(deg));
  p.drawText(left, 12, QObject::tr("tets by minimum dihedral angle (degrees)"));
  return QPixmap::fromImage(img);
}

}  // namespace

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
  view_ = new foxi::qt::ViewWidget;
  view_->setMinimumSize(480, 360);

  // The view and its controls.
  auto* centre = new QWidget;
  auto* cv = new QVBoxLayout(centre);
  auto* bar = new QHBoxLayout;
  auto button = [&](const QString& text, auto slot) {
    auto* b = new QPushButton(text);
    connect(b, &QPushButton::clicked, view_, slot);
    bar->addWidget(b);
    return b;
  };
  button(tr("Draw"), &foxi::qt::ViewWidget::draw);
  button(tr("Stop"), &foxi::qt::ViewWidget::stop);
  button(tr("Go on"), &foxi::qt::ViewWidget::resume);
  button(tr("Step"), &foxi::qt::ViewWidget::step_once);
  button(tr("Undraw"), &foxi::qt::ViewWidget::undraw);
  button(tr("Region"), &foxi::qt::ViewWidget::push_region);
  button(tr("Back"), &foxi::qt::ViewWidget::pop_region);
  auto* save = new QPushButton(tr("Save picture..."));
  connect(save, &QPushButton::clicked, this, [this] {
    const QString f =
        QFileDialog::getSaveFileName(this, tr("Save the view's picture"), QString(), tr("PNG (*.png)"));
    QString error;
    if (!f.isEmpty() && !view_->save_picture(f, &error)) param_error_->setText(error);
  });
  bar->addWidget(save);
  fraction_ = new QSlider(Qt::Horizontal);
  fraction_->setRange(0, 1000);
  fraction_->setValue(1000);
  fraction_->setToolTip(tr("fraction of the displayed set drawn: drawing or undrawing follows it"));
  connect(fraction_, &QSlider::sliderMoved, this, [this](int v) { view_->set_fraction(v / 1000.0); });
  cv->addLayout(bar);
  auto* slider_row = new QHBoxLayout;
  slider_row->addWidget(new QLabel(tr("fraction drawn")));
  slider_row->addWidget(fraction_, 1);
  cv->addLayout(slider_row);
  auto* fields = new QHBoxLayout;
  field_box_ = new QComboBox;
  field_box_->setMinimumContentsLength(12);
  field_box_->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
  cmap_box_ = new QComboBox;
  for (const char* m : {"viridis", "cividis", "coolwarm", "rainbow"}) cmap_box_->addItem(m);
  fields->addWidget(new QLabel(tr("field")));
  fields->addWidget(field_box_, 1);
  fields->addWidget(new QLabel(tr("colour map")));
  fields->addWidget(cmap_box_);
  shrink_box_ = new QDoubleSpinBox;
  shrink_box_->setRange(0.1, 1.0);
  shrink_box_->setSingleStep(0.05);
  shrink_box_->setValue(1.0);
  shrink_box_->setToolTip(tr("each tet scaled about its centroid: see between them"));
  connect(shrink_box_, qOverload<double>(&QDoubleSpinBox::valueChanged), this,
          [this](double v) { set_shrink(v); });
  // A value in the field's display unit (a range's end), taken when typed in full.
  auto value_box = [] {
    auto* b = new QDoubleSpinBox;
    b->setDecimals(3);
    b->setRange(-1e12, 1e12);
    b->setKeyboardTracking(false);
    b->setMaximumWidth(110);
    return b;
  };
  graded_box_ = new QCheckBox(tr("graded"));
  graded_box_->setToolTip(tr("each face's colour interpolated from its corners (foxi render --graded)"));
  range_on_ = new QCheckBox(tr("range"));
  range_on_->setToolTip(tr("the colour range in the legend's unit (otherwise the values' own range)"));
  range_lo_ = value_box();
  range_hi_ = value_box();
  range_hi_->setValue(1);
  auto recolour = [this] {
    std::optional<std::pair<double, double>> r;
    if (range_on_->isChecked()) r = std::pair(range_lo_->value(), range_hi_->value());
    if (!set_colouring(graded_box_->isChecked(), r)) param_error_->setText(tr("the range needs low < high"));
  };
  connect(graded_box_, &QCheckBox::toggled, this, recolour);
  connect(range_on_, &QCheckBox::toggled, this, recolour);
  connect(range_lo_, qOverload<double>(&QDoubleSpinBox::valueChanged), this, recolour);
  connect(range_hi_, qOverload<double>(&QDoubleSpinBox::valueChanged), this, recolour);
  fields->addWidget(graded_box_);
  fields->addWidget(range_on_);
  fields->addWidget(range_lo_);
  fields->addWidget(range_hi_);
  fields->addWidget(new QLabel(tr("shrink")));
  fields->addWidget(shrink_box_);
  cv->addLayout(fields);
  // The field tools: isosurface, threshold, clip (by the field shown; disabled without one).
  auto* tools = new QHBoxLayout;
  iso_on_ = new QCheckBox(tr("isosurface"));
  iso_on_->setToolTip(tr("the solid where the field is at least the isovalue, cut at the isosurface"));
  iso_slider_ = new QSlider(Qt::Horizontal);
  iso_slider_->setRange(0, 1000);
  iso_slider_->setValue(500);
  iso_value_ = new QLabel;
  iso_value_->setMinimumWidth(80);
  iso_only_ = new QCheckBox(tr("surface only"));
  threshold_on_ = new QCheckBox(tr("threshold"));
  threshold_on_->setToolTip(tr("only the tets whose value (at the centroid) lies in the range"));
  threshold_lo_ = value_box();
  threshold_hi_ = value_box();
  clip_on_ = new QCheckBox(tr("clip"));
  clip_on_->setToolTip(
      tr("only the whole tets behind the plane (its normal, along the axis chosen, points to "
         "the part cut away)"));
  clip_axis_ = new QComboBox;
  for (const char* a : {"+x", "+y", "+z", "-x", "-y", "-z"}) clip_axis_->addItem(a);
  clip_slider_ = new QSlider(Qt::Horizontal);
  clip_slider_->setRange(0, 1000);
  clip_slider_->setValue(500);
  tools->addWidget(iso_on_);
  tools->addWidget(iso_slider_, 3);
  tools->addWidget(iso_value_);
  tools->addWidget(iso_only_);
  tools->addWidget(threshold_on_);
  tools->addWidget(threshold_lo_);
  tools->addWidget(threshold_hi_);
  tools->addWidget(clip_on_);
  tools->addWidget(clip_axis_);
  tools->addWidget(clip_slider_, 2);
  cv->addLayout(tools);
  regions_ = new QListWidget;
  regions_->setFlow(QListView::LeftToRight);
  regions_->setMaximumHeight(32);
  regions_->setToolTip(tr("the regions shown (foxi render --regions)"));
  connect(regions_, &QListWidget::itemChanged, this, [this] {
    if (filling_) return;
    std::vector<std::int32_t> hidden;
    for (int i = 0; i < regions_->count(); ++i)
      if (regions_->item(i)->checkState() != Qt::Checked)
        hidden.push_back(regions_->item(i)->data(Qt::UserRole).toInt());
    set_hidden_regions(hidden);
  });
  auto* region_row = new QHBoxLayout;
  region_row->addWidget(new QLabel(tr("regions shown")));
  region_row->addWidget(regions_, 1);
  cv->addLayout(region_row);
  for (QCheckBox* c : {iso_on_, iso_only_, threshold_on_, clip_on_})
    connect(c, &QCheckBox::toggled, this, [this] { apply_field_tools(); });
  connect(iso_slider_, &QSlider::valueChanged, this, [this] { apply_field_tools(); });
  connect(clip_slider_, &QSlider::valueChanged, this, [this] { apply_field_tools(); });
  connect(clip_axis_, qOverload<int>(&QComboBox::currentIndexChanged), this, [this] { apply_field_tools(); });
  for (QDoubleSpinBox* b : {threshold_lo_, threshold_hi_})
    connect(b, qOverload<double>(&QDoubleSpinBox::valueChanged), this, [this] { apply_field_tools(); });
  auto* vrow = new QHBoxLayout;
  vrow->addWidget(view_, 1);
  legend_ = new QLabel;
  legend_->setFixedWidth(150);
  legend_->setAlignment(Qt::AlignTop);
  vrow->addWidget(legend_);
  cv->addLayout(vrow, 1);
  auto pick_field = [this] {
    if (filling_) return;
    const QString f = field_box_->currentIndex() <= 0 ? QString() : field_box_->currentText();
    set_field(f, cmap_box_->currentText());
  };
  connect(field_box_, qOverload<int>(&QComboBox::currentIndexChanged), this, pick_field);
  connect(cmap_box_, qOverload<int>(&QComboBox::currentIndexChanged), this, pick_field);
  setCentralWidget(centre);

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
  // Projects: save and reopen the whole state; the folder is then autosaved; the recent ones listed.
  auto* projects = new QHBoxLayout;
  auto* save_p = new QPushButton(tr("Save project..."));
  auto* open_p = new QPushButton(tr("Open project..."));
  auto* recent = new QPushButton(tr("Recent"));
  auto* recent_menu = new QMenu(recent);
  recent->setMenu(recent_menu);
  // After a save or an open of `folder`: it heads the recent list (QSettings) and is autosaved.
  auto adopt = [this](bool ok, const QString& folder, const QString& why) {
    if (!ok) {
      show_error(why);
      return;
    }
    QSettings settings;
    QStringList list = settings.value("recent_projects").toStringList();
    list.removeAll(folder);
    list.prepend(folder);
    while (list.size() > 8) list.removeLast();
    settings.setValue("recent_projects", list);
    set_autosave_folder(folder);
  };
  auto open_folder = [this, adopt](const QString& folder) {
    QString why;
    adopt(open_project(folder, &why), folder, why);
  };
  connect(save_p, &QPushButton::clicked, this, [this, adopt] {
    const QString f = QFileDialog::getExistingDirectory(this, tr("Save the project into a folder"));
    if (f.isEmpty()) return;
    QString why;
    adopt(save_project(f, &why), f, why);
  });
  connect(open_p, &QPushButton::clicked, this, [this, open_folder] {
    const QString f = QFileDialog::getExistingDirectory(this, tr("Open a project folder"));
    if (!f.isEmpty()) open_folder(f);
  });
  connect(recent_menu, &QMenu::aboutToShow, this, [recent_menu, open_folder] {
    recent_menu->clear();
    for (const QString& f : QSettings().value("recent_projects").toStringList())
      recent_menu->addAction(f, [open_folder, f] { open_folder(f); });
  });
  projects->addWidget(save_p);
  projects->addWidget(open_p);
  projects->addWidget(recent);
  lv->addLayout(projects);
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

  // The mesh's quality report and its dihedral-angle histogram.
  auto* mesh_panel = new QWidget;
  auto* mv = new QVBoxLayout(mesh_panel);
  quality_text_ = new QPlainTextEdit;
  quality_text_->setReadOnly(true);
  quality_text_->setLineWrapMode(QPlainTextEdit::NoWrap);
  histogram_ = new QLabel;
  mv->addWidget(histogram_);
  mv->addWidget(quality_text_, 1);
  mesh_panel->setMinimumWidth(320);
  auto* mesh_dock = new QDockWidget(tr("Mesh quality"));
  mesh_dock->setObjectName("mesh");
  mesh_dock->setWidget(mesh_panel);
  addDockWidget(Qt::RightDockWidgetArea, mesh_dock);

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
  history_table_ = new QTableWidget(0, 5);
  history_table_->setHorizontalHeaderLabels(
      {tr("run"), tr("parameters"), tr("tets"), tr("key results"), tr("time")});
  history_table_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  history_table_->horizontalHeader()->setSectionResizeMode(3, QHeaderView::Stretch);
  history_table_->verticalHeader()->hide();
  history_table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  auto* history_dock = new QDockWidget(tr("Run history"));
  history_dock->setObjectName("history");
  history_dock->setWidget(history_table_);
  addDockWidget(Qt::BottomDockWidgetArea, history_dock);

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
}

void Workbench::launch(std::function<std::shared_ptr<Outcome>()> work, const QString& what,
                       std::shared_ptr<std::atomic<bool>> cancel,
                       std::shared_ptr<std::atomic<int>> permille) {
  job_ = std::make_unique<Job>();
  job_->what = what;
  job_->cancel = std::move(cancel);
  job_->permille = std::move(permille);
  connect(&job_->watcher, &QFutureWatcher<std::shared_ptr<Outcome>>::finished, this, &Workbench::on_job_done);
  job_->watcher.setFuture(QtConcurrent::run([work = std::move(work)] {
    // The worker (and the threads it starts: TetGen, the solver's, which inherit it) niced, so
    // that on a machine with few cores the GUI thread still gets the CPU when it needs it.
    setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 10);
    return work();
  }));
  mesh_button_->setEnabled(false);
  solve_button_->setEnabled(false);
  cancel_button_->setEnabled(true);
  progress_->setValue(0);
  progress_->setFormat(what + " %p%");
  poll_->start();
}

// What a mesh or solve job needs, copied from the GUI thread's state when it starts.
struct JobInput {
  std::string path;
  std::vector<ParameterOverride> overrides;
  bool mesh = true, solve = false;
  std::shared_ptr<const Mesh> old_mesh;    // solve only: the mesh to solve on
  std::shared_ptr<const Model> old_model;  // and the model it came from
  int width = 1, height = 1;
  std::optional<Camera> camera;  // the view's camera stays across a remesh (compare before and after)
  Colouring colouring;
  double shrink = 1;
  std::shared_ptr<std::atomic<bool>> cancel;
  std::shared_ptr<std::atomic<int>> permille;
};

namespace {

// The worker's part: mesh (mesh_model) and/or solve (thermal) and the new picture's view.
std::shared_ptr<Outcome> run_job(const JobInput& in) {
  auto out = std::make_shared<Outcome>();
  const auto t0 = Clock::now();
  auto progress = [cancel = in.cancel, permille = in.permille](std::string_view stage, double f) {
    permille->store(stage_index(stage) * 10000 + int(std::lround(std::clamp(f, 0.0, 1.0) * 1000)));
    return !cancel->load();
  };
  // Cancel pressed after the last progress call (a direct solve may not call it at all) still
  // discards the result: the previous state stays.
  auto cancelled = [&] {
    if (!in.cancel->load()) return false;
    out->cancelled = true;
    out->error = "cancelled";
    return true;
  };
  try {
    std::shared_ptr<Mesh> mesh;
    std::shared_ptr<const Model> model = in.old_model;
    if (in.mesh) {
      ModelMeshOptions options;
      options.override_origin = "the parameter table";
      options.progress = progress;
      // A solve to follow: the model's conditions and materials checked before meshing, as foxi solve does.
      if (in.solve) options.physics = Physics::thermal;
      MeshedModel mm = mesh_model(in.path, in.overrides, options);
      if (cancelled()) return out;
      mesh = std::make_shared<Mesh>(std::move(mm.mesh));
      out->quality = mesh_quality_report(*mesh, mm.conforming);
      model = std::make_shared<const Model>(std::move(mm.model));
      out->meshed = true;
      out->seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    } else {
      // The shown mesh stays as it is: the solve writes its fields into a copy.
      mesh = std::make_shared<Mesh>(*in.old_mesh);
    }
    const auto t1 = Clock::now();
    if (in.solve) {
      if (!in.mesh) check_physics(*model, Physics::thermal);
      ThermalParams params = thermal_params_from_model(*model, *mesh);
      params.solver.progress = progress;
      const ThermalReport report = solve_thermal(*mesh, params);
      if (cancelled()) return out;
      out->results = thermal_results(*mesh, report);
      out->results.model = in.path;
      out->results.physics = "thermal";
      for (const ParameterOverride& o : in.overrides)
        out->results.parameters.push_back({o.name, o.expression});
      out->solve_seconds = std::chrono::duration<double>(Clock::now() - t1).count();
      out->solved = true;
    }
    build_display(*out, *mesh, in.solve ? "temperature" : "", in.colouring, in.shrink, in.width, in.height,
                  in.camera ? &*in.camera : nullptr);
    out->mesh = std::move(mesh);
    out->model = std::move(model);
    out->overrides = in.overrides;
    out->ok = true;
  } catch (const Cancelled&) {
    out->cancelled = true;
    out->error = "cancelled";
  } catch (const IoError& e) {
    out->bad_input = true;
    out->error = what_of(e);
  } catch (const std::exception& e) {
    out->error = what_of(e);
  }
  return out;
}

}  // namespace

bool Workbench::start_job(bool mesh, bool solve) {
  if (busy() || model_path_.isEmpty()) return false;
  JobInput in;
  in.path = model_path_.toStdString();
  in.overrides = overrides();
  // Only what changed reruns: a solve remeshes first when the parameters changed since the mesh.
  const bool stale = !mesh_ || !meshed_model_ || !same_overrides(in.overrides, meshed_overrides_);
  in.mesh = mesh || stale;
  in.solve = solve;
  in.old_mesh = mesh_;
  in.old_model = meshed_model_;
  in.width = view_->width();
  in.height = view_->height();
  if (view_->camera()) in.camera = *view_->camera();
  in.colouring = colouring();
  in.shrink = shrink_;
  in.cancel = std::make_shared<std::atomic<bool>>(false);
  in.permille = std::make_shared<std::atomic<int>>(0);
  const QString what = in.mesh && in.solve ? tr("meshing and solving")
                       : in.mesh           ? tr("meshing")
                                           : tr("solving");
  auto cancel = in.cancel;
  auto permille = in.permille;
  launch([in = std::move(in)] { return run_job(in); }, what, cancel, permille);
  return true;
}

bool Workbench::start_mesh() { return start_job(true, false); }
bool Workbench::start_solve() { return start_job(false, true); }

bool Workbench::set_field(const QString& field, const QString& color_map) {
  if (busy() || !mesh_) return false;
  std::shared_ptr<const Mesh> mesh = mesh_;
  const std::string f = field.toStdString();
  const double shrink = shrink_;
  const int w = view_->width(), h = view_->height();
  std::optional<Camera> cam;
  if (view_->camera()) cam = *view_->camera();
  if (pending_camera_) cam = std::exchange(pending_camera_, std::nullopt);
  field_ = field;
  color_map_ = color_map;
  auto work = [mesh, f, c = colouring(), shrink, w, h, cam]() {
    auto out = std::make_shared<Outcome>();
    try {
      build_display(*out, *mesh, f, c, shrink, w, h, cam ? &*cam : nullptr);
      out->mesh = mesh;
      out->ok = true;
    } catch (const std::exception& e) {
      out->error = what_of(e);
    }
    return out;
  };
  launch(work, tr("colouring"), std::make_shared<std::atomic<bool>>(false),
         std::make_shared<std::atomic<int>>(0));
  return true;
}

namespace {

QJsonArray numbers(const double* v, int n) {
  QJsonArray a;
  for (int i = 0; i < n; ++i) a.append(v[i]);
  return a;
}

void read_numbers(const QJsonValue& v, double* out, int n) {
  const QJsonArray a = v.toArray();
  if (a.size() != n)
    throw std::runtime_error("a camera vector of " + std::to_string(n) + " numbers expected");
  for (int i = 0; i < n; ++i) out[i] = a[i].toDouble();
}

QJsonArray overrides_json(const std::vector<ParameterOverride>& ov) {
  QJsonArray a;
  for (const ParameterOverride& o : ov)
    a.append(QJsonArray{QString::fromStdString(o.name), QString::fromStdString(o.expression)});
  return a;
}

std::vector<ParameterOverride> overrides_of(const QJsonValue& v) {
  std::vector<ParameterOverride> ov;
  for (const QJsonValue& e : v.toArray())
    ov.push_back({e.toArray().at(0).toString().toStdString(), e.toArray().at(1).toString().toStdString()});
  return ov;
}

}  // namespace

// What a save writes, taken on the GUI thread (the state may change meanwhile) and written on any thread.
struct ProjectSnapshot {
  std::filesystem::path dir;
  QJsonObject json;
  std::shared_ptr<const Mesh> mesh;
};

namespace {

// Writes the mesh under a new name, then project.json naming it (both DurableFile: each whole or
// not at all), then removes the mesh file the previous project.json named.
void write_project(ProjectSnapshot snap) {
  const std::filesystem::path& dir = snap.dir;
  std::filesystem::create_directories(dir);
  std::filesystem::path old_mesh;
  if (std::filesystem::exists(dir / "project.json")) {
    QFile f(QString::fromStdString((dir / "project.json").string()));
    if (f.open(QIODevice::ReadOnly)) {
      const QString m = QJsonDocument::fromJson(f.readAll()).object()["mesh"].toString();
      if (!m.isEmpty()) old_mesh = dir / m.toStdString();
    }
  }
  if (snap.mesh) {
    // A new name each save: the previous project.json names a whole mesh until the new one is in.
    std::string name;
    for (int i = 1;; ++i) {
      name = "mesh-" + std::to_string(i) + ".vtu";
      if (!std::filesystem::exists(dir / name) && dir / name != old_mesh) break;
    }
    write_mesh(*snap.mesh, dir / name);
    snap.json["mesh"] = QString::fromStdString(name);
  }
  DurableFile out(dir / "project.json");
  out.write(QJsonDocument(snap.json).toJson().toStdString());
  out.commit();
  if (!old_mesh.empty() && old_mesh.filename().string() != snap.json["mesh"].toString().toStdString() &&
      old_mesh.filename().string().rfind("mesh-", 0) == 0)
    std::filesystem::remove(old_mesh);
}

}  // namespace

ProjectSnapshot Workbench::project_snapshot(const QString& folder) const {
  if (model_path_.isEmpty()) throw std::runtime_error("no model to save");
  ProjectSnapshot snap;
  snap.dir = folder.toStdString();
  snap.mesh = mesh_;
  QJsonObject& p = snap.json;
  p["format"] = "foxi-workbench project 1";
  p["model"] = QFileInfo(model_path_).absoluteFilePath();
  p["overrides"] = overrides_json(overrides());
  p["field"] = field_;
  p["color_map"] = color_map_;
  p["graded"] = graded_;
  if (range_) p["range"] = QJsonArray{range_->first, range_->second};
  QJsonArray hidden;
  for (std::int32_t r : hidden_) hidden.append(r);
  p["hidden_regions"] = hidden;
  p["shrink"] = shrink_;
  if (const Camera* c = view_->camera()) {
    QJsonObject cam;
    cam["perspective"] = c->perspective;
    cam["eye"] = numbers(c->eye, 3);
    cam["at"] = numbers(c->at, 3);
    cam["up"] = numbers(c->up, 3);
    cam["fov_deg"] = c->fov_deg;
    cam["ortho_height"] = c->ortho_height;
    p["camera"] = cam;
  }
  QJsonArray history;
  for (const HistoryRow& h : history_) {
    QJsonObject row;
    row["parameters"] = overrides_json(h.parameters);
    row["mesh"] = double(h.mesh);
    row["tets"] = double(h.tets);
    row["seconds"] = h.seconds;
    row["results"] = QString::fromStdString(results_json(h.results));
    history.append(row);
  }
  p["history"] = history;
  if (has_results_) p["results"] = QString::fromStdString(results_json(results_));
  p["mesh_overrides"] = overrides_json(meshed_overrides_);
  if (selection_.any()) {
    QJsonObject sel;
    QJsonArray iso;
    for (double v : selection_.iso) iso.append(v);
    sel["iso"] = iso;
    sel["iso_only"] = selection_.iso_only;
    if (selection_.threshold)
      sel["threshold"] = QJsonArray{selection_.threshold->first, selection_.threshold->second};
    if (selection_.clip) {
      QJsonArray c = numbers(selection_.clip->p, 3);
      for (int k = 0; k < 3; ++k) c.append(selection_.clip->n[k]);
      sel["clip"] = c;
    }
    p["selection"] = sel;
  }
  return snap;
}

bool Workbench::save_project(const QString& folder, QString* error) {
  try {
    if (busy()) throw std::runtime_error("a job is running: save when it ends");
    if (autosaving_.isRunning()) autosaving_.waitForFinished();
    write_project(project_snapshot(folder));
    return true;
  } catch (const std::exception& e) {
    if (error) *error = QString::fromStdString(e.what());
    return false;
  }
}

void Workbench::set_autosave_folder(const QString& folder) {
  autosave_folder_ = folder;
  if (folder.isEmpty()) autosave_timer_->stop();
}

void Workbench::changed() {
  if (!autosave_folder_.isEmpty() && !model_path_.isEmpty() && !autosave_timer_->isActive())
    autosave_timer_->start();
}

void Workbench::autosave() {
  // Not while a job runs (its result is the next change) or the previous autosave still writes.
  if (busy() || autosaving_.isRunning()) {
    autosave_timer_->start();
    return;
  }
  try {
    ProjectSnapshot snap = project_snapshot(autosave_folder_);
    autosaving_ = QtConcurrent::run([snap = std::move(snap)]() -> QString {
      try {
        write_project(snap);
        return {};
      } catch (const std::exception& e) {
        return QString::fromStdString(e.what());
      }
    });
    ++autosaves_;
  } catch (const std::exception& e) {
    progress_->setFormat(tr("autosave: %1").arg(QString::fromStdString(e.what())));
  }
}

void Workbench::wait_autosave() {
  if (autosaving_.isRunning()) autosaving_.waitForFinished();
}

bool Workbench::open_project(const QString& folder, QString* error) {
  try {
    if (busy()) throw std::runtime_error("a job is running");
    const std::filesystem::path dir = folder.toStdString();
    QFile f(QString::fromStdString((dir / "project.json").string()));
    if (!f.open(QIODevice::ReadOnly))
      throw std::runtime_error((dir / "project.json").string() + ": cannot read");
    QJsonParseError perr;
    const QJsonDocument doc = QJsonDocument::fromJson(f.readAll(), &perr);
    if (doc.isNull())
      throw std::runtime_error((dir / "project.json").string() + ": " + perr.errorString().toStdString());
    const QJsonObject p = doc.object();
    if (p["format"].toString() != "foxi-workbench project 1")
      throw std::runtime_error((dir / "project.json").string() + ": not a foxi-workbench project");
    QString why;
    if (!open_model(p["model"].toString(), &why)) throw std::runtime_error(why.toStdString());
    std::map<std::string, std::string> trial;
    for (const ParameterOverride& o : overrides_of(p["overrides"])) trial[o.name] = o.expression;
    if (!apply_overrides(trial, &why)) throw std::runtime_error(why.toStdString());
    field_ = p["field"].toString();
    color_map_ = p["color_map"].toString("viridis");
    graded_ = p["graded"].toBool();
    range_.reset();
    if (p.contains("range"))
      range_ = std::pair(p["range"].toArray().at(0).toDouble(), p["range"].toArray().at(1).toDouble());
    hidden_.clear();
    for (const QJsonValue& v : p["hidden_regions"].toArray()) hidden_.push_back(v.toInt());
    shrink_ = p["shrink"].toDouble(1);
    history_.clear();
    for (const QJsonValue& v : p["history"].toArray()) {
      const QJsonObject o = v.toObject();
      HistoryRow h;
      h.parameters = overrides_of(o["parameters"]);
      h.mesh = std::size_t(o["mesh"].toDouble());
      h.tets = std::size_t(o["tets"].toDouble());
      h.seconds = o["seconds"].toDouble();
      h.results = parse_results_json(o["results"].toString().toStdString());
      history_.push_back(std::move(h));
    }
    has_results_ = p.contains("results");
    if (has_results_) results_ = parse_results_json(p["results"].toString().toStdString());
    if (!p["mesh"].toString().isEmpty()) {
      mesh_ = std::make_shared<const Mesh>(read_mesh(dir / p["mesh"].toString().toStdString()));
      meshed_model_ = model_;
      meshed_overrides_ = overrides_of(p["mesh_overrides"]);
      mesh_serial_ = history_.empty() ? 1 : history_.back().mesh;
    }
    if (p.contains("camera")) {
      const QJsonObject c = p["camera"].toObject();
      Camera cam;
      cam.perspective = c["perspective"].toBool(true);
      read_numbers(c["eye"], cam.eye, 3);
      read_numbers(c["at"], cam.at, 3);
      read_numbers(c["up"], cam.up, 3);
      cam.fov_deg = c["fov_deg"].toDouble(30);
      cam.ortho_height = c["ortho_height"].toDouble(1);
      pending_camera_ = cam;
    }
    selection_ = {};
    if (p.contains("selection")) {
      const QJsonObject sel = p["selection"].toObject();
      for (const QJsonValue& v : sel["iso"].toArray()) selection_.iso.push_back(v.toDouble());
      selection_.iso_only = sel["iso_only"].toBool();
      if (sel.contains("threshold"))
        selection_.threshold = std::pair(sel["threshold"].toArray().at(0).toDouble(),
                                         sel["threshold"].toArray().at(1).toDouble());
      if (sel.contains("clip")) {
        double c[6];
        read_numbers(sel["clip"], c, 6);
        Plane pl;
        for (int k = 0; k < 3; ++k) pl.p[k] = c[k], pl.n[k] = c[k + 3];
        selection_.clip = pl;
      }
    }
    selection_field_ = field_;  // the display that follows applies it
    {
      const QSignalBlocker q1(graded_box_), q2(range_on_), q3(range_lo_), q4(range_hi_), q5(shrink_box_);
      graded_box_->setChecked(graded_);
      range_on_->setChecked(range_.has_value());
      if (range_) range_lo_->setValue(range_->first), range_hi_->setValue(range_->second);
      shrink_box_->setValue(shrink_);
    }
    if (has_results_) show_results();
    refresh_history();
    if (mesh_) set_field(field_, color_map_);
    return true;
  } catch (const std::exception& e) {
    if (error) *error = QString::fromStdString(e.what());
    return false;
  }
}

Colouring Workbench::colouring() const {
  return Colouring{color_map_.toStdString(), graded_, range_, hidden_};
}

bool Workbench::set_hidden_regions(std::vector<std::int32_t> hidden) {
  hidden_ = std::move(hidden);
  return !mesh_ || set_field(field_, color_map_);
}

bool Workbench::set_colouring(bool graded, std::optional<std::pair<double, double>> range) {
  if (range && !(range->first < range->second && std::isfinite(range->first) && std::isfinite(range->second)))
    return false;
  graded_ = graded;
  range_ = range;
  {
    const QSignalBlocker q1(graded_box_), q2(range_on_), q3(range_lo_), q4(range_hi_);
    graded_box_->setChecked(graded);
    range_on_->setChecked(range.has_value());
    if (range) {
      range_lo_->setValue(range->first);
      range_hi_->setValue(range->second);
    }
  }
  return !mesh_ || field_.isEmpty() || set_field(field_, color_map_);
}

bool Workbench::set_shrink(double shrink) {
  if (!(shrink > 0 && shrink <= 1)) return false;
  shrink_ = shrink;
  if (shrink_box_->value() != shrink) {
    const QSignalBlocker quiet(shrink_box_);
    shrink_box_->setValue(shrink);
  }
  return !mesh_ || set_field(field_, color_map_);
}

void Workbench::cancel() {
  if (job_) job_->cancel->store(true);
}

void Workbench::on_job_done() {
  std::shared_ptr<Outcome> out = job_->watcher.result();
  const QString what = job_->what;
  job_.reset();
  poll_->stop();
  mesh_button_->setEnabled(true);
  solve_button_->setEnabled(true);
  cancel_button_->setEnabled(false);
  progress_->setValue(out && out->ok ? 1000 : 0);
  if (!out || !out->ok) {
    const QString why = out ? out->error : tr("no result");
    last_error_ = why;
    last_error_bad_input_ = out && out->bad_input;
    progress_->setFormat(what + ": " + why);
    if (!out || !out->cancelled) param_error_->setText(why);
    emit finished(false);
    return;
  }
  last_error_.clear();
  last_error_bad_input_ = false;
  progress_->setFormat(what + tr(": done in %1 s").arg(out->seconds + out->solve_seconds, 0, 'f', 2));
  if (out->meshed) {
    mesh_ = out->mesh;
    meshed_model_ = out->model;
    meshed_overrides_ = out->overrides;
    mesh_seconds_ = out->seconds;
    ++mesh_serial_;
    if (out->quality) {
      quality_text_->setPlainText(QString::fromStdString(format_quality_report(*out->quality)));
      histogram_->setPixmap(histogram_pixmap(*out->quality));
    }
    has_results_ = false;
    field_.clear();
  }
  if (out->solved) {
    mesh_ = out->mesh;
    results_ = out->results;
    results_.mesh_seconds = mesh_seconds_;
    results_.solve_seconds = out->solve_seconds;
    has_results_ = true;
    field_ = "temperature";
  }
  if (!out->meshed && !out->solved) mesh_ = out->mesh;
  view_->set_view(out->mesh, std::move(out->view));
  view_->set_probe_values(std::move(out->probe), out->probe_unit);
  mesh_bounds(*out->mesh, bounds_lo_, bounds_hi_);
  view_->set_base(std::move(out->base));
  if (out->has_scale && out->choice) {
    view_->set_field_source(*out->choice, out->step, out->scale, out->iso_cache);
    if (!range_) {  // the range boxes start from the automatic range
      const QSignalBlocker q1(range_lo_), q2(range_hi_);
      range_lo_->setValue(out->unit.to_display(out->scale.lo));
      range_hi_->setValue(out->unit.to_display(out->scale.hi));
    }
    unit_ = out->unit;
    field_lo_ = out->corner_lo;
    field_hi_ = out->corner_hi;
    // The same field (a new colour map, shrink or solve): its tools stay; another field: they go.
    if (selection_field_ != field_) selection_ = {};
    selection_field_ = field_;
    QString why;
    if (selection_.any() && !view_->set_selection(selection_, &why)) selection_ = {};
  } else {
    selection_ = {};
    selection_field_.clear();
  }
  show_selection();
  if (out->has_scale)
    legend_->setPixmap(legend_pixmap(out->scale, out->unit, out->field_label, view_->height()));
  else
    legend_->clear();
  refresh_fields();
  if (out->meshed && !out->solved) add_history(out->seconds);
  if (out->solved) {
    show_results();
    add_history(mesh_seconds_ + out->solve_seconds);  // the mesh's row gets the results
  }
  changed();
  emit finished(true);
}

bool Workbench::set_selection(const FieldSelection& selection, QString* error) {
  if (!view_->set_selection(selection, error)) return false;
  changed();
  selection_ = selection;
  selection_field_ = field_;
  show_selection();
  return true;
}

void Workbench::show_selection() {
  filling_ = true;
  const bool field = !selection_field_.isEmpty() && view_->has_view() && field_hi_ >= field_lo_;
  for (QWidget* w :
       std::initializer_list<QWidget*>{iso_on_, iso_slider_, iso_only_, threshold_on_, threshold_lo_,
                                       threshold_hi_, clip_on_, clip_axis_, clip_slider_})
    w->setEnabled(field);
  const FieldSelection& s = selection_;
  const QSignalBlocker b1(iso_on_), b2(iso_slider_), b3(iso_only_), b4(threshold_on_), b5(threshold_lo_),
      b6(threshold_hi_), b7(clip_on_), b8(clip_axis_), b9(clip_slider_);
  iso_on_->setChecked(!s.iso.empty());
  iso_only_->setChecked(s.iso_only);
  const double span = field_hi_ - field_lo_;
  if (!s.iso.empty() && span > 0)
    iso_slider_->setValue(int(std::lround(1000 * (s.iso.front() - field_lo_) / span)));
  const double iso = s.iso.empty() ? field_lo_ + span * iso_slider_->value() / 1000.0 : s.iso.front();
  iso_value_->setText(
      field ? QString("%1 %2").arg(unit_.to_display(iso), 0, 'g', 5).arg(QString::fromStdString(unit_.symbol))
            : QString());
  threshold_on_->setChecked(s.threshold.has_value());
  if (field && !s.threshold) {
    threshold_lo_->setValue(unit_.to_display(field_lo_));
    threshold_hi_->setValue(unit_.to_display(field_hi_));
  } else if (s.threshold) {
    threshold_lo_->setValue(unit_.to_display(s.threshold->first));
    threshold_hi_->setValue(unit_.to_display(s.threshold->second));
  }
  clip_on_->setChecked(s.clip.has_value());
  if (s.clip) {
    // An axis plane of the slider's: its axis, side and position; any other plane leaves the controls.
    for (int k = 0; k < 3; ++k)
      if (s.clip->n[k] != 0 && s.clip->n[(k + 1) % 3] == 0 && s.clip->n[(k + 2) % 3] == 0 &&
          bounds_hi_[k] > bounds_lo_[k]) {
        clip_axis_->setCurrentIndex(s.clip->n[k] > 0 ? k : k + 3);
        clip_slider_->setValue(
            int(std::lround(1000 * (s.clip->p[k] - bounds_lo_[k]) / (bounds_hi_[k] - bounds_lo_[k]))));
      }
  }
  filling_ = false;
}

void Workbench::apply_field_tools() {
  if (filling_ || selection_field_.isEmpty()) return;
  FieldSelection s;
  const double span = field_hi_ - field_lo_;
  if (iso_on_->isChecked()) {
    s.iso = {field_lo_ + span * iso_slider_->value() / 1000.0};
    s.iso_only = iso_only_->isChecked();
  }
  if (threshold_on_->isChecked())
    s.threshold = {unit_.to_si(threshold_lo_->value()), unit_.to_si(threshold_hi_->value())};
  if (clip_on_->isChecked()) {
    Plane p;
    const int k = clip_axis_->currentIndex() % 3;
    for (int j = 0; j < 3; ++j) {
      p.p[j] = 0.5 * (bounds_lo_[j] + bounds_hi_[j]);
      p.n[j] = j == k ? (clip_axis_->currentIndex() < 3 ? 1 : -1) : 0;
    }
    p.p[k] = bounds_lo_[k] + (bounds_hi_[k] - bounds_lo_[k]) * clip_slider_->value() / 1000.0;
    s.clip = p;
  }
  QString why;
  if (!set_selection(s, &why)) param_error_->setText(why);
}

void Workbench::refresh_fields() {
  filling_ = true;
  field_box_->clear();
  field_box_->addItem(tr("(regions)"));
  if (mesh_)
    for (const Field& f : mesh_->fields) field_box_->addItem(QString::fromStdString(f.name));
  const int i = field_.isEmpty() ? 0 : field_box_->findText(field_);
  field_box_->setCurrentIndex(std::max(i, 0));
  cmap_box_->setCurrentText(color_map_);
  regions_->clear();
  if (mesh_)
    for (const Region& r : mesh_->regions) {
      auto* item =
          new QListWidgetItem(r.name.empty() ? QString::number(r.id) : QString::fromStdString(r.name));
      item->setData(Qt::UserRole, r.id);
      item->setFlags(item->flags() | Qt::ItemIsUserCheckable);
      item->setCheckState(std::find(hidden_.begin(), hidden_.end(), r.id) == hidden_.end() ? Qt::Checked
                                                                                           : Qt::Unchecked);
      regions_->addItem(item);
    }
  filling_ = false;
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
  // A solve of the mesh the last row made completes that row (one row per model state).
  const bool complete = has_results_ && !history_.empty() && history_.back().results.values.empty() &&
                        history_.back().mesh == row.mesh;
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
    if (v.key)
      key += QString("%1 %2 %3; ")
                 .arg(QString::fromStdString(v.name))
                 .arg(v.value, 0, 'g', 5)
                 .arg(QString::fromStdString(v.unit));
  history_table_->setItem(i, 0, new QTableWidgetItem(QString::number(i + 1)));
  history_table_->setItem(i, 1, new QTableWidgetItem(params.isEmpty() ? tr("(as in the file)") : params));
  history_table_->setItem(i, 2, new QTableWidgetItem(QString::number(row.tets)));
  history_table_->setItem(i, 3, new QTableWidgetItem(row.results.values.empty() ? tr("meshed only") : key));
  history_table_->setItem(i, 4, new QTableWidgetItem(QString("%1 s").arg(row.seconds, 0, 'f', 2)));
}

void Workbench::refresh_history() {
  history_table_->setRowCount(int(history_.size()));
  for (std::size_t i = 0; i < history_.size(); ++i) fill_history_row(int(i), history_[i]);
}

}  // namespace foxi::workbench
