// foxi-workbench's view panel: the view, its draw controls, the field, colouring and field tools.
#include "workbench.hpp"
#include "workbench_parts.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QHBoxLayout>
#include <QImage>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPainter>
#include <QProgressBar>
#include <QPushButton>
#include <QScrollArea>
#include <QScrollBar>
#include <QSignalBlocker>
#include <QSlider>
#include <QTimer>
#include <QVBoxLayout>
#include <QtConcurrent/QtConcurrentRun>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <initializer_list>
#include <tuple>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "foxi/model/validate.hpp"
#include "foxi/viz/animation.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/legend.hpp"
#include "foxi/viz/rasterizer.hpp"

namespace foxi::workbench {
namespace {

// The view's rows of controls, scrolled sideways where the window is narrower than they are (a
// 1366-pixel laptop screen with the side panels; they need about 800 pixels): exactly as tall as
// the rows, and the scroll bar only while it shows. Without it the rows set the window's least
// width (1670 pixels with the panels), wider than such screens.
class ControlRows : public QScrollArea {
 public:
  ControlRows() {
    setWidgetResizable(true);
    setFrameShape(QFrame::NoFrame);
    setVerticalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
    setHorizontalScrollBarPolicy(Qt::ScrollBarAsNeeded);
    setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Fixed);
    // The bar comes and goes with the window's width and with the rows' own (a field shown widens
    // them): the height asked for follows it, so the bar never covers the last row.
    connect(horizontalScrollBar(), &QScrollBar::rangeChanged, this, [this] { updateGeometry(); });
  }
  QSize sizeHint() const override { return {widget() ? widget()->sizeHint().width() : 0, rows_height()}; }
  QSize minimumSizeHint() const override { return {160, rows_height()}; }

 private:
  int rows_height() const {
    if (!widget()) return 0;
    const bool bar = horizontalScrollBar()->maximum() > 0;
    return widget()->sizeHint().height() + (bar ? horizontalScrollBar()->sizeHint().height() : 0);
  }
};

}  // namespace

void build_display(Outcome& out, const Mesh& source, const std::string& field, const Colouring& colouring,
                   double shrink, int w, int h, const Camera* camera) {
  // The deformed shape: a moved copy (the same fields) drawn, checked as foxi render --deform checks it.
  if (colouring.deform) {
    auto moved = std::make_shared<Mesh>(source);
    deform_by_field(*moved, colouring.deform->field, colouring.deform->scale);
    const ValidationReport report = validate_and_repair(*moved);
    if (!report.ok()) {
      std::string why = "the mesh deformed by " + colouring.deform->field + " x " +
                        std::to_string(colouring.deform->scale) + " is not usable:";
      for (const std::string& line : describe(report)) why += " " + line;
      throw std::runtime_error(why);
    }
    out.view_mesh = std::move(moved);
  }
  const Mesh& mesh = out.view_mesh ? *out.view_mesh : source;
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
    out.unit = unit_for(choice.field->unit, std::isfinite(lo) ? std::max(std::abs(lo), std::abs(hi)) : 0,
                        colouring.si_units);
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
    out.volume_scale = scale;
    if (!colouring.range && !colouring.graded) {
      const std::vector<double>& corner = *out.iso_cache->corner;
      std::vector<double> corners;
      for (std::uint32_t t : out.base)
        corners.insert(corners.end(), corner.begin() + std::ptrdiff_t(4 * t),
                       corner.begin() + std::ptrdiff_t(4 * t + 4));
      if (const std::optional<AutoScale> a = automatic_scale(out.base.empty() ? corner : corners, map))
        out.volume_scale = a->scale;
    }
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

// A colour bar with ticks (colormap.hpp's entries and nice_ticks), in the field's display unit.
void Workbench::show_legend() {
  if (!legend_scale_) return;
  const LegendScales& l = *legend_scale_;
  legend_->setPixmap(
      legend_pixmap(view_->volume() ? l.volume_scale : l.scale, l.unit, l.label, view_->height()));
}

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

QPushButton* Workbench::build_view_panel() {
  view_ = new foxi::qt::ViewWidget;
  view_->setMinimumSize(400, 300);  // with the side panels, the window fits a 1366 x 768 screen

  // The view and, above it, its rows of controls (ControlRows).
  auto* centre = new QWidget;
  auto* outer = new QVBoxLayout(centre);
  auto* rows = new QWidget;
  auto* cv = new QVBoxLayout(rows);
  cv->setContentsMargins(0, 0, 0, 0);
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
  auto* region = new QPushButton(tr("Region"));
  region->setToolTip(tr("the tets drawn become the displayed set, the camera framed on them"));
  connect(region, &QPushButton::clicked, this, [this] {
    QString why;
    if (!view_->push_region(&why)) param_error_->setText(why);
  });
  bar->addWidget(region);
  button(tr("Back"), &foxi::qt::ViewWidget::pop_region);
  auto* save = new QPushButton(tr("Save picture..."));
  connect(save, &QPushButton::clicked, this, [this] {
    const QString f =
        QFileDialog::getSaveFileName(this, tr("Save the view's picture"), QString(), tr("PNG (*.png)"));
    QString error;
    if (!f.isEmpty() && !view_->save_picture(f, &error)) param_error_->setText(error);
  });
  bar->addWidget(save);
  // The movie: a turning camera (foxi movie --mode rotate), written on a worker; the button cancels it.
  movie_button_ = new QPushButton(tr("Save movie..."));
  movie_button_->setToolTip(
      tr("the camera turned once around, 48 frames, as foxi movie --mode rotate draws them: .gif, .apng or "
         "numbered PNG frames (frame_%04d.png)"));
  movie_progress_ = new QProgressBar;
  movie_progress_->setRange(0, 1000);
  movie_progress_->setMaximumWidth(120);
  movie_progress_->setVisible(false);
  connect(movie_button_, &QPushButton::clicked, this, [this] {
    if (movie_) {
      cancel_movie();
      return;
    }
    const QString f = QFileDialog::getSaveFileName(this, tr("Save a movie of the view"), QString(),
                                                   tr("Movies (*.gif *.apng);;PNG frames (*.png)"));
    QString error;
    if (!f.isEmpty() && !save_movie(f, 48, &error)) param_error_->setText(error);
  });
  bar->addWidget(movie_button_);
  bar->addWidget(movie_progress_);
  fraction_ = new QSlider(Qt::Horizontal);
  fraction_->setRange(0, 1000);
  fraction_->setValue(1000);
  fraction_->setToolTip(tr("fraction of the displayed set drawn: drawing or undrawing follows it"));
  connect(fraction_, &QSlider::sliderMoved, this, [this](int v) { view_->set_fraction(v / 1000.0); });
  cv->addLayout(bar);
  auto* slider_row = new QHBoxLayout;
  slider_row->addWidget(new QLabel(tr("fraction drawn")));
  slider_row->addWidget(fraction_, 1);
  cv->addLayout(slider_row);  // shrink and the deformed shape join this row below
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
  // The deformed shape: the displacement (a thermal stress solve's) times the scale.
  deform_on_ = new QCheckBox(tr("deformed x"));
  deform_on_->setToolTip(
      tr("the mesh moved by the displacement times the scale (foxi render --deform displacement:SCALE); "
         "not Delaunay in general: drawn in MPVO order, as the status line says"));
  deform_scale_ = new QDoubleSpinBox;
  deform_scale_->setRange(0, 1e9);
  deform_scale_->setDecimals(1);
  deform_scale_->setValue(100);
  deform_scale_->setKeyboardTracking(false);
  deform_scale_->setMaximumWidth(90);
  auto deform = [this] {
    if (filling_) return;
    std::optional<Deform> d;
    if (deform_on_->isChecked()) d = Deform{"displacement", deform_scale_->value()};
    if (!set_deform(d)) param_error_->setText(tr("the deformed shape: not while a job runs"));
  };
  connect(deform_on_, &QCheckBox::toggled, this, deform);
  connect(deform_scale_, qOverload<double>(&QDoubleSpinBox::valueChanged), this, deform);
  cv->addLayout(fields);
  // The field tools: isosurface, threshold, clip (by the field shown; disabled without one).
  auto* tools = new QHBoxLayout;
  iso_on_ = new QCheckBox(tr("isosurface"));
  iso_on_->setObjectName("isosurface");
  iso_on_->setToolTip(tr("the solid where the field is at least the isovalue, cut at the isosurface"));
  iso_slider_ = new QSlider(Qt::Horizontal);
  iso_slider_->setRange(0, 1000);
  iso_slider_->setValue(500);
  iso_value_ = new QLabel;
  iso_value_->setMinimumWidth(80);
  // Several isosurfaces at once (foxi render --iso a,b,...): the slider's and these.
  iso_more_ = new QLineEdit;
  iso_more_->setObjectName("more_isovalues");
  iso_more_->setPlaceholderText(tr("more isovalues"));
  iso_more_->setToolTip(
      tr("more isovalues in the legend's unit, separated by commas: drawn with the slider's (foxi render "
         "--iso a,b,...)"));
  iso_more_->setMaximumWidth(140);
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
  slice_on_ = new QCheckBox(tr("slice"));
  slice_on_->setObjectName("slice");
  slice_on_->setToolTip(
      tr("the plane's cut through the tets shown, coloured by the field (foxi render --slice); not with "
         "isovalues"));
  slice_axis_ = new QComboBox;
  for (const char* a : {"x", "y", "z"}) slice_axis_->addItem(a);
  slice_axis_->setCurrentIndex(2);
  slice_slider_ = new QSlider(Qt::Horizontal);
  slice_slider_->setRange(0, 1000);
  slice_slider_->setValue(500);
  tools->addWidget(iso_on_);
  tools->addWidget(iso_slider_, 3);
  tools->addWidget(iso_value_);
  tools->addWidget(iso_more_);
  tools->addWidget(iso_only_);
  // The subsets and cuts on a row of their own (one row for all made the window ~2000 pixels wide).
  auto* cuts = new QHBoxLayout;
  cuts->addWidget(threshold_on_);
  cuts->addWidget(threshold_lo_);
  cuts->addWidget(threshold_hi_);
  cuts->addWidget(clip_on_);
  cuts->addWidget(clip_axis_);
  cuts->addWidget(clip_slider_, 2);
  cuts->addWidget(slice_on_);
  cuts->addWidget(slice_axis_);
  cuts->addWidget(slice_slider_, 2);
  // Translucency and volume rendering (issue 23), composited exactly: ViewWidget::set_xray, set_volume.
  // The boxes show what the view draws (composite_changed), not what was last clicked.
  for (const bool volume : {false, true}) {
    auto* box = new QCheckBox(volume ? tr("volume") : tr("X-ray"));
    box->setObjectName(volume ? "volume" : "xray");
    box->setToolTip(volume ? tr("a volume rendering of the field shown (foxi render --volume)")
                           : tr("every region translucent but the smallest, isosurfaces translucent inside "
                                "(foxi render --region-opacity, --iso-opacity)"));
    connect(box, &QCheckBox::toggled, this, [this, box, volume](bool on) {
      QString why;
      if (!(volume ? view_->set_volume(on, &why) : view_->set_xray(on, &why))) {
        param_error_->setText(why);
        const QSignalBlocker block(box);
        box->setChecked(volume ? view_->volume() : view_->xray());
      }
    });
    (volume ? volume_box_ : xray_box_) = box;
  }
  connect(view_, &foxi::qt::ViewWidget::composite_changed, this, [this](bool xray, bool volume) {
    const QSignalBlocker b1(xray_box_), b2(volume_box_);
    xray_box_->setChecked(xray);
    volume_box_->setChecked(volume);
    show_legend();  // the volume's scale, or the picture's
  });
  tools->addWidget(xray_box_);
  tools->addWidget(volume_box_);
  // Shrink and the deformed shape beside the fraction slider: each row of tools stays short enough
  // that the window fits a 1680-pixel screen with its panels.
  slider_row->addWidget(new QLabel(tr("shrink")));
  slider_row->addWidget(shrink_box_);
  slider_row->addWidget(deform_on_);
  slider_row->addWidget(deform_scale_);
  for (QSlider* sl : {iso_slider_, clip_slider_, slice_slider_}) sl->setMinimumWidth(100);
  iso_more_->setMinimumWidth(90);
  cv->addLayout(tools);
  cv->addLayout(cuts);
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
  regions_->setObjectName("regions_shown");
  // A box per material: its regions shown or hidden at once, through the regions' own path (the
  // hidden region set, foxi render --regions of the others); partly checked when only some are.
  materials_ = new QListWidget;
  materials_->setObjectName("materials_shown");
  materials_->setFlow(QListView::LeftToRight);
  materials_->setMaximumHeight(32);
  materials_->setToolTip(tr("the materials shown: all their regions (foxi render --regions)"));
  connect(materials_, &QListWidget::itemChanged, this, [this](QListWidgetItem* item) {
    if (filling_ || item->checkState() == Qt::PartiallyChecked) return;
    set_material_shown(item->data(Qt::UserRole).toUInt(), item->checkState() == Qt::Checked);
  });
  auto* region_row = new QHBoxLayout;
  region_row->addWidget(new QLabel(tr("regions shown")));
  region_row->addWidget(regions_, 1);
  region_row->addWidget(new QLabel(tr("materials")));
  region_row->addWidget(materials_, 1);
  cv->addLayout(region_row);
  for (QCheckBox* c : {iso_on_, iso_only_, threshold_on_, clip_on_, slice_on_})
    connect(c, &QCheckBox::toggled, this, [this] { apply_field_tools(); });
  connect(slice_slider_, &QSlider::valueChanged, this, [this] { apply_field_tools(); });
  connect(slice_axis_, qOverload<int>(&QComboBox::currentIndexChanged), this,
          [this] { apply_field_tools(); });
  connect(iso_slider_, &QSlider::valueChanged, this, [this] { apply_field_tools(); });
  connect(iso_more_, &QLineEdit::editingFinished, this, [this] { apply_field_tools(); });
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
  auto* controls = new ControlRows;
  controls->setObjectName("view_controls");
  controls->setWidget(rows);
  outer->addWidget(controls);
  outer->addLayout(vrow, 1);
  auto pick_field = [this] {
    if (filling_) return;
    const QString f = field_box_->currentIndex() <= 0 ? QString() : field_box_->currentText();
    set_field(f, cmap_box_->currentText());
  };
  connect(field_box_, qOverload<int>(&QComboBox::currentIndexChanged), this, pick_field);
  connect(cmap_box_, qOverload<int>(&QComboBox::currentIndexChanged), this, pick_field);
  setCentralWidget(centre);
  return save;
}

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
      const auto t0 = std::chrono::steady_clock::now();
      build_display(*out, *mesh, f, c, shrink, w, h, cam ? &*cam : nullptr);
      out->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
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

Colouring Workbench::colouring() const {
  return Colouring{color_map_.toStdString(), graded_, range_, hidden_, deform_, si_units_};
}

bool Workbench::set_deform(std::optional<Deform> deform) {
  if (busy() || !mesh_ || (deform && !std::isfinite(deform->scale))) return false;
  const std::optional<Deform> before = deform_;
  deform_ = std::move(deform);
  if (!set_field(field_, color_map_)) {
    deform_ = before;
    return false;
  }
  deform_before_ = before;  // back to it if the moved mesh is refused
  return true;
}

bool Workbench::set_hidden_regions(std::vector<std::int32_t> hidden) {
  hidden_ = std::move(hidden);
  show_region_boxes();
  return !mesh_ || set_field(field_, color_map_);
}

bool Workbench::set_material_shown(std::uint32_t material, bool shown) {
  if (!mesh_) return false;
  std::vector<std::int32_t> hidden;
  bool found = false;
  for (const Region& r : mesh_->regions) {
    const bool hide =
        r.material == material ? !shown : std::find(hidden_.begin(), hidden_.end(), r.id) != hidden_.end();
    found = found || r.material == material;
    if (hide) hidden.push_back(r.id);
  }
  if (!found) return false;
  return set_hidden_regions(std::move(hidden));
}

void Workbench::show_region_boxes() {
  if (!regions_ || !materials_) return;
  const bool was_filling = filling_;
  filling_ = true;
  auto is_hidden = [this](std::int32_t id) {
    return std::find(hidden_.begin(), hidden_.end(), id) != hidden_.end();
  };
  for (int i = 0; i < regions_->count(); ++i)
    regions_->item(i)->setCheckState(is_hidden(regions_->item(i)->data(Qt::UserRole).toInt()) ? Qt::Unchecked
                                                                                              : Qt::Checked);
  for (int i = 0; i < materials_->count(); ++i) {
    const std::uint32_t m = materials_->item(i)->data(Qt::UserRole).toUInt();
    int shown = 0, hidden = 0;
    if (mesh_)
      for (const Region& r : mesh_->regions)
        if (r.material == m) ++(is_hidden(r.id) ? hidden : shown);
    materials_->item(i)->setCheckState(hidden == 0  ? Qt::Checked
                                       : shown == 0 ? Qt::Unchecked
                                                    : Qt::PartiallyChecked);
  }
  filling_ = was_filling;
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
  for (QWidget* w : std::initializer_list<QWidget*>{
           iso_on_, iso_slider_, iso_more_, iso_only_, threshold_on_, threshold_lo_, threshold_hi_, clip_on_,
           clip_axis_, clip_slider_, slice_on_, slice_axis_, slice_slider_, volume_box_})
    w->setEnabled(field);  // the volume renders the field shown (the x-ray needs none)
  const FieldSelection& s = selection_;
  const QSignalBlocker b0(iso_more_), b1(iso_on_), b2(iso_slider_), b3(iso_only_), b4(threshold_on_),
      b5(threshold_lo_), b6(threshold_hi_), b7(clip_on_), b8(clip_axis_), b9(clip_slider_), b10(slice_on_),
      b11(slice_axis_), b12(slice_slider_);
  iso_on_->setChecked(!s.iso.empty());
  iso_only_->setChecked(s.iso_only);
  const double span = field_hi_ - field_lo_;
  if (!s.iso.empty() && span > 0)
    iso_slider_->setValue(int(std::lround(1000 * (s.iso.front() - field_lo_) / span)));
  const double iso = s.iso.empty() ? field_lo_ + span * iso_slider_->value() / 1000.0 : s.iso.front();
  iso_value_->setText(
      field ? QString("%1 %2").arg(unit_.to_display(iso), 0, 'g', 5).arg(QString::fromStdString(unit_.symbol))
            : QString());
  QStringList more;
  for (std::size_t i = 1; i < s.iso.size(); ++i) more << QString::number(unit_.to_display(s.iso[i]), 'g', 6);
  if (!s.iso.empty() || !field) iso_more_->setText(more.join(", "));
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
  slice_on_->setChecked(s.slice.has_value());
  if (s.slice) {
    for (int k = 0; k < 3; ++k)
      if (s.slice->n[k] != 0 && s.slice->n[(k + 1) % 3] == 0 && s.slice->n[(k + 2) % 3] == 0 &&
          bounds_hi_[k] > bounds_lo_[k]) {
        slice_axis_->setCurrentIndex(k);
        slice_slider_->setValue(
            int(std::lround(1000 * (s.slice->p[k] - bounds_lo_[k]) / (bounds_hi_[k] - bounds_lo_[k]))));
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
    for (const QString& t : iso_more_->text().split(',', Qt::SkipEmptyParts)) {
      bool ok = false;
      const double v = t.trimmed().toDouble(&ok);
      if (!ok || !std::isfinite(v)) {
        param_error_->setText(tr("more isovalues: '%1' is not a number (values in %2, separated by commas)")
                                  .arg(t.trimmed(), QString::fromStdString(unit_.symbol)));
        return;
      }
      s.iso.push_back(unit_.to_si(v));
    }
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
  if (slice_on_->isChecked()) {
    Plane p;
    const int k = slice_axis_->currentIndex();
    for (int j = 0; j < 3; ++j) {
      p.p[j] = 0.5 * (bounds_lo_[j] + bounds_hi_[j]);
      p.n[j] = j == k ? 1 : 0;
    }
    p.p[k] = bounds_lo_[k] + (bounds_hi_[k] - bounds_lo_[k]) * slice_slider_->value() / 1000.0;
    s.slice = p;
  }
  QString why;
  if (!set_selection(s, &why)) {
    param_error_->setText(why);
    show_selection();  // the controls back to what is drawn
  }
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
  const bool displaced = mesh_ && mesh_->find_field("displacement");
  deform_on_->setEnabled(displaced);
  deform_scale_->setEnabled(displaced);
  deform_on_->setChecked(deform_.has_value());
  if (deform_) deform_scale_->setValue(deform_->scale);
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
  materials_->clear();
  if (mesh_)
    for (std::uint32_t m = 0; m < mesh_->materials.size(); ++m) {
      if (std::none_of(mesh_->regions.begin(), mesh_->regions.end(),
                       [m](const Region& r) { return r.material == m; }))
        continue;
      auto* item = new QListWidgetItem(QString::fromStdString(mesh_->materials[m].name));
      item->setData(Qt::UserRole, m);
      item->setFlags(item->flags() | Qt::ItemIsUserCheckable);
      materials_->addItem(item);
    }
  show_region_boxes();
  filling_ = false;
}

bool Workbench::save_movie(const QString& path, int frames, QString* error) {
  auto fail = [&](const QString& why) {
    if (error) *error = why;
    return false;
  };
  if (movie_) return fail(tr("a movie is being written: cancel it or wait"));
  if (!view_->has_view()) return fail(tr("no picture to make a movie of"));
  if (frames < 2) return fail(tr("a movie needs at least 2 frames"));
  const std::string out = path.toStdString();
  const QString ext = QFileInfo(path).suffix().toLower();
  enum class Kind { gif, apng, png_frames } kind;
  if (path.contains('%')) {
    if (!frame_pattern(out))
      return fail(tr("%1: a frame name needs one %d or %0Nd and no other %").arg(path));
    kind = Kind::png_frames;
  } else if (ext == "gif") {
    kind = Kind::gif;
  } else if (ext == "apng") {
    kind = Kind::apng;
  } else {
    return fail(tr("%1: give .gif, .apng or a numbered frame name like frames/frame_%04d.png").arg(path));
  }
  ViewMovie input;
  try {
    input = view_->view()->movie_input();  // a copy: the view goes on while the worker draws
  } catch (const std::exception& e) {
    return fail(what_of(e));
  }
  MovieParams mp;
  mp.rotate = true;
  mp.frames = frames;
  std::shared_ptr<const Mesh> mesh = view_->mesh();
  movie_ = std::make_unique<MovieJob>();
  auto work = [mesh, input = std::move(input), mp, out, kind, cancel = movie_->cancel,
               permille = movie_->permille]() -> QString {
    setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 10);  // as the jobs' workers
    try {
      AnimationParams ap;
      ap.width = input.width;
      ap.height = input.height;
      std::unique_ptr<AnimationWriter> writer = kind == Kind::gif    ? open_gif(out, ap)
                                                : kind == Kind::apng ? open_apng(out, ap)
                                                                     : open_png_frames(out, ap);
      make_view_movie(
          *mesh, input, mp, [&](const Framebuffer& fb) { writer->add(fb); },
          [&](std::string_view, double f) {
            permille->store(int(std::lround(std::clamp(f, 0.0, 1.0) * 1000)));
            return !cancel->load();
          });
      writer->finish();
      return {};
    } catch (const MovieCancelled&) {
      return QStringLiteral("cancelled");
    } catch (const std::exception& e) {
      return QString::fromStdString(e.what());
    }
  };
  connect(&movie_->watcher, &QFutureWatcher<QString>::finished, this, [this, path] {
    const QString why = movie_->watcher.result();
    // Not deleted inside its own watcher's signal: after it returns.
    MovieJob* done = movie_.release();
    QTimer::singleShot(0, this, [done] { delete done; });
    movie_button_->setText(tr("Save movie..."));
    movie_progress_->setVisible(false);
    if (why.isEmpty())
      progress_->setFormat(tr("movie written: %1").arg(path));
    else if (why != "cancelled")
      param_error_->setText(tr("movie: %1").arg(why));
    emit movie_finished(why.isEmpty(), why.isEmpty() ? path : why);
  });
  movie_->poll.setInterval(100);
  connect(&movie_->poll, &QTimer::timeout, this, [this] {
    if (movie_) movie_progress_->setValue(movie_->permille->load());
  });
  movie_->poll.start();
  movie_->watcher.setFuture(QtConcurrent::run(std::move(work)));
  movie_button_->setText(tr("Cancel movie"));
  movie_progress_->setValue(0);
  movie_progress_->setVisible(true);
  return true;
}

void Workbench::cancel_movie() {
  if (movie_) movie_->cancel->store(true);
}

}  // namespace foxi::workbench
