// foxi-workbench's mesh panel: the mesh settings (mesher, global and per-part sizes, quality bound,
// refinement boxes, refine from the current result), given to mesh_model's options by every mesh job,
// and the quality report with its dihedral-angle histogram.
#include "workbench.hpp"
#include "workbench_parts.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QDockWidget>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QImage>
#include <QLabel>
#include <QLineEdit>
#include <QPainter>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QScrollArea>
#include <QSignalBlocker>
#include <QTableWidget>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>

#include "foxi/mesher/mesher.hpp"
#include "foxi/model/units.hpp"

namespace foxi::workbench {

namespace {

// A length typed in the panel: "0.2 mm", or a bare number in the model's length unit (`scale`
// metres), as foxi mesh reads its lengths. Throws ExpressionError with the reason.
double parse_length(const QString& text, double scale) {
  Quantity q = evaluate_expression(text.trimmed().toStdString(),
                                   [](std::string_view) { return std::optional<Quantity>(); });
  if (q.dims == kDimensionless)
    q.value *= scale;
  else if (q.dims != kLength)
    throw ExpressionError("'" + text.toStdString() + "' is not a length");
  return q.value;
}

// A length in the model's unit, as the panel shows it.
QString length_text(double metres, double scale, const std::string& unit) {
  return QString("%1 %2").arg(metres / scale, 0, 'g', 6).arg(QString::fromStdString(unit));
}

const char* const kBoxColumns[] = {"x0", "y0", "z0", "x1", "y1", "z1", "size"};

// A cell's text, its item kept when it has one: the tables are refilled from inside their own
// cellChanged, which must not delete the item it reports.
void set_cell(QTableWidget* table, int row, int column, const QString& text, bool editable = true) {
  QTableWidgetItem* item = table->item(row, column);
  if (!item) {
    item = new QTableWidgetItem;
    table->setItem(row, column, item);
  }
  item->setText(text);
  item->setFlags(editable ? item->flags() | Qt::ItemIsEditable : item->flags() & ~Qt::ItemIsEditable);
}

// A settings table of the panel: `name` for tests, the columns' headers, no row numbers, 20 px rows.
QTableWidget* settings_table(const char* name, const QStringList& columns) {
  auto* table = new QTableWidget(0, int(columns.size()));
  table->setObjectName(name);
  table->setHorizontalHeaderLabels(columns);
  table->verticalHeader()->hide();
  table->verticalHeader()->setDefaultSectionSize(20);
  return table;
}

}  // namespace

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

void apply_mesh_settings(ModelMeshOptions& options, const MeshSettings& s, const Mesh* result,
                         const std::string& shown_field) {
  options.mesher = s.mesher;
  options.max_size = s.max_size;
  options.part_sizes = s.part_sizes;
  options.quality = s.quality;
  options.sizes.boxes = s.boxes;
  if (s.refine_from_result) {
    // The field named, else the one shown when it is a node field, else the result's first.
    std::string field = s.refine_field;
    if (field.empty() && result && refine_field(*result, shown_field)) field = shown_field;
    options.refine_from = {
        .mesh = result, .field = field, .target_error = s.target_error, .origin = "the current result"};
  }
}

QString mesher_summary(const MeshedModel& m) {
  QString text;
  if (m.mesher == Mesher::cgal) {
    text = QObject::tr(
               "mesher: CGAL Mesh_3 (regular triangulation, vertex weights) in %1 s; region volumes "
               "against the PLC's: worst change %2%")
               .arg(m.cgal.seconds, 0, 'f', 2)
               .arg(100 * m.cgal.worst_volume_change, 0, 'g', 3);
    if (m.cgal.boxes > 0) text += QObject::tr("; refinement boxes: %1").arg(m.cgal.boxes);
  } else {
    text = QObject::tr("mesher: TetGen (switches %1), conforming Delaunay refinement")
               .arg(QString::fromStdString(m.report.switches));
  }
  if (m.refined)
    text += QObject::tr("\nrefined from the result's '%1': relative gradient error %2 (Zienkiewicz-Zhu)")
                .arg(QString::fromStdString(m.refined->field))
                .arg(m.refined->relative_error, 0, 'g', 3);
  return text;
}

bool same_mesh_settings(const MeshSettings& a, const MeshSettings& b) {
  auto same_box = [](const RefinementBox& x, const RefinementBox& y) {
    return std::equal(x.lo, x.lo + 3, y.lo) && std::equal(x.hi, x.hi + 3, y.hi) && x.size == y.size;
  };
  auto same_part = [](const PartSize& x, const PartSize& y) {
    return x.part == y.part && x.max_size == y.max_size;
  };
  return a.mesher == b.mesher && a.max_size == b.max_size && a.quality == b.quality &&
         std::equal(a.part_sizes.begin(), a.part_sizes.end(), b.part_sizes.begin(), b.part_sizes.end(),
                    same_part) &&
         std::equal(a.boxes.begin(), a.boxes.end(), b.boxes.begin(), b.boxes.end(), same_box) &&
         a.refine_from_result == b.refine_from_result && a.refine_field == b.refine_field &&
         a.target_error == b.target_error;
}

QString mesh_settings_text(const MeshSettings& s, double scale, const std::string& unit) {
  auto length = [&](double metres) { return length_text(metres, scale, unit); };
  QStringList lines;
  lines << QObject::tr("mesher: %1").arg(s.mesher == Mesher::cgal ? "CGAL Mesh_3" : "TetGen");
  lines << QObject::tr("global size: %1").arg(s.max_size ? length(*s.max_size) : QObject::tr("the model's"));
  QStringList parts;
  for (const PartSize& p : s.part_sizes) parts << QString::fromStdString(p.part) + " " + length(p.max_size);
  lines << QObject::tr("part sizes: %1").arg(parts.isEmpty() ? QObject::tr("the model's") : parts.join(", "));
  for (std::size_t i = 0; i < s.boxes.size(); ++i) {
    const RefinementBox& b = s.boxes[i];
    auto corner = [&](const double* c) {
      return QString("(%1, %2, %3)")
          .arg(c[0] / scale, 0, 'g', 6)
          .arg(c[1] / scale, 0, 'g', 6)
          .arg(c[2] / scale, 0, 'g', 6);
    };
    lines << QObject::tr("refinement box %1: %2 to %3 %4, size %5")
                 .arg(i + 1)
                 .arg(corner(b.lo), corner(b.hi), QString::fromStdString(unit), length(b.size));
  }
  if (s.boxes.empty()) lines << QObject::tr("refinement boxes: none");
  lines << QObject::tr("quality bound: %1")
               .arg(s.quality ? QString::number(*s.quality, 'g', 6) : QObject::tr("the default"));
  if (s.refine_from_result)
    lines << QObject::tr("refined from the result's %1, target error %2")
                 .arg(s.refine_field.empty() ? QObject::tr("field shown")
                                             : "'" + QString::fromStdString(s.refine_field) + "'")
                 .arg(s.target_error, 0, 'g', 6);
  return lines.join('\n');
}

bool Workbench::set_mesh_settings(const MeshSettings& settings, QString* error) {
  auto refuse = [&](const QString& why) {
    if (error) *error = why;
    if (mesh_ui_) mesh_ui_->error->setText(why);
    return false;
  };
  if (busy()) return refuse(tr("a job is running"));
  // The checks mesh_model makes first (check_mesh_options), now: a refinement source stands in for
  // the result, which the job takes when it starts.
  ModelMeshOptions trial;
  static const Mesh placeholder;
  apply_mesh_settings(trial, settings, &placeholder, "");
  try {
    check_mesh_options(trial);
  } catch (const MesherError& e) {
    return refuse(what_of(e));
  }
  for (const PartSize& p : settings.part_sizes)
    if (!model_ || std::none_of(model_->parts.begin(), model_->parts.end(),
                                [&](const Part& q) { return q.name == p.part; }))
      return refuse(tr("no part named '%1' in the model").arg(QString::fromStdString(p.part)));
  // A project keeps the settings: a change of them is autosaved (an edit that changes nothing is not).
  const bool change = !same_mesh_settings(settings, mesh_settings_);
  mesh_settings_ = settings;
  if (mesh_ui_) mesh_ui_->error->clear();
  refresh_mesh_controls();
  if (change) changed();
  return true;
}

void Workbench::on_mesh_controls_edited() {
  MeshControls& ui = *mesh_ui_;
  const double scale = model_ ? model_->length_scale : 1;
  MeshSettings s = mesh_settings_;
  auto fail = [&](const QString& why) { ui.error->setText(why); };
  try {
    s.mesher = ui.mesher->currentIndex() == 1 ? Mesher::cgal : Mesher::tetgen;
    s.max_size.reset();
    if (!ui.max_size->text().trimmed().isEmpty()) s.max_size = parse_length(ui.max_size->text(), scale);
    s.quality.reset();
    if (!ui.quality->text().trimmed().isEmpty()) {
      bool ok = false;
      s.quality = ui.quality->text().trimmed().toDouble(&ok);
      if (!ok)
        return fail(
            tr("the quality bound takes a number (a radius-edge ratio), not '%1'").arg(ui.quality->text()));
    }
    s.part_sizes.clear();
    for (int r = 0; r < ui.parts->rowCount(); ++r) {
      const QTableWidgetItem* name = ui.parts->item(r, 0);
      const QTableWidgetItem* size = ui.parts->item(r, 1);
      if (!name || !size || size->text().trimmed().isEmpty()) continue;
      s.part_sizes.push_back(
          {.part = name->text().toStdString(), .max_size = parse_length(size->text(), scale)});
    }
    s.boxes.clear();
    for (int r = 0; r < ui.boxes->rowCount(); ++r) {
      double v[7];
      for (int c = 0; c < 7; ++c) {
        const QTableWidgetItem* it = ui.boxes->item(r, c);
        if (!it || it->text().trimmed().isEmpty())
          return fail(tr("refinement box %1: give %2").arg(r + 1).arg(kBoxColumns[c]));
        v[c] = parse_length(it->text(), scale);
      }
      RefinementBox b;
      for (int k = 0; k < 3; ++k) {
        b.lo[k] = std::min(v[k], v[k + 3]);
        b.hi[k] = std::max(v[k], v[k + 3]);
      }
      b.size = v[6];
      s.boxes.push_back(b);
    }
    s.refine_from_result = ui.refine->isChecked();
    s.refine_field =
        ui.refine_field->currentIndex() <= 0 ? std::string() : ui.refine_field->currentText().toStdString();
    bool ok = false;
    s.target_error = ui.target_error->text().trimmed().toDouble(&ok);
    if (!ok)
      return fail(tr("the target error takes a number (e.g. 0.05), not '%1'").arg(ui.target_error->text()));
  } catch (const ExpressionError& e) {
    return fail(what_of(e));
  }
  set_mesh_settings(s);
}

void Workbench::refresh_mesh_controls() {
  if (!mesh_ui_) return;
  if (mesh_settings_model_ != model_path_) {  // another model: its own [mesh] table, no leftovers
    mesh_settings_ = {};
    mesh_settings_model_ = model_path_;
  }
  MeshControls& ui = *mesh_ui_;
  const MeshSettings& s = mesh_settings_;
  const double scale = model_ ? model_->length_scale : 1;
  const std::string unit = model_ ? model_->length_unit : "m";
  const QSignalBlocker b1(ui.mesher), b2(ui.max_size), b3(ui.quality), b4(ui.parts), b5(ui.boxes),
      b6(ui.refine), b7(ui.refine_field), b8(ui.target_error);
  ui.mesher->setCurrentIndex(s.mesher == Mesher::cgal ? 1 : 0);
  ui.max_size->setText(s.max_size ? length_text(*s.max_size, scale, unit) : QString());
  ui.max_size->setPlaceholderText(model_ && model_->mesh.max_size > 0
                                      ? tr("model: %1").arg(length_text(model_->mesh.max_size, scale, unit))
                                      : tr("none"));
  ui.quality->setText(s.quality ? QString::number(*s.quality, 'g', 6) : QString());
  ui.quality->setPlaceholderText(s.mesher == Mesher::cgal ? tr("CGAL: 2")
                                 : model_ && model_->mesh.quality >= 0
                                     ? tr("model: %1").arg(model_->mesh.quality)
                                     : tr("1.414"));
  // One row per part: the size set here (empty: the model's, shown beside it).
  ui.parts->setRowCount(model_ ? int(model_->parts.size()) : 0);
  // Every part's row in sight (up to 5; the table scrolls past that).
  ui.parts->setFixedHeight(ui.parts->horizontalHeader()->sizeHint().height() +
                           20 * std::clamp(ui.parts->rowCount(), 1, 5) + 8);
  for (int r = 0; model_ && r < int(model_->parts.size()); ++r) {
    const Part& part = model_->parts[std::size_t(r)];
    QString mine, models;
    for (const PartSize& p : s.part_sizes)
      if (p.part == part.name) mine = length_text(p.max_size, scale, unit);
    for (const PartSize& p : model_->mesh.part_sizes)
      if (p.part == part.name) models = length_text(p.max_size, scale, unit);
    set_cell(ui.parts, r, 0, QString::fromStdString(part.name), false);
    set_cell(ui.parts, r, 1, mine);
    set_cell(ui.parts, r, 2, models, false);
  }
  ui.boxes->setRowCount(int(s.boxes.size()));
  for (int r = 0; r < int(s.boxes.size()); ++r) {
    const RefinementBox& b = s.boxes[std::size_t(r)];
    const double v[7] = {b.lo[0], b.lo[1], b.lo[2], b.hi[0], b.hi[1], b.hi[2], b.size};
    for (int c = 0; c < 7; ++c) set_cell(ui.boxes, r, c, QString::number(v[c] / scale, 'g', 6));
  }
  ui.refine->setChecked(s.refine_from_result);
  // The current result's node fields (refine_field's choices); the first entry: the field shown.
  ui.refine_field->clear();
  ui.refine_field->addItem(tr("the field shown"));
  if (mesh_)
    for (const Field& f : mesh_->fields)
      if (f.location == FieldLocation::node) ui.refine_field->addItem(QString::fromStdString(f.name));
  const int at =
      s.refine_field.empty() ? 0 : ui.refine_field->findText(QString::fromStdString(s.refine_field));
  if (at < 0) ui.refine_field->addItem(QString::fromStdString(s.refine_field));
  ui.refine_field->setCurrentIndex(at < 0 ? ui.refine_field->count() - 1 : at);
  ui.target_error->setText(QString::number(s.target_error, 'g', 6));
}

void Workbench::build_mesh_panel() {
  mesh_ui_ = std::make_unique<MeshControls>();
  MeshControls& ui = *mesh_ui_;
  auto* mesh_panel = new QWidget;
  auto* mv = new QVBoxLayout(mesh_panel);
  mv->setSpacing(3);  // the settings above the report, in the window's height
  // The settings: every edit goes to mesh_settings_ (refused values shown in red, the settings kept).
  auto* form = new QFormLayout;
  ui.mesher = new QComboBox;
  ui.mesher->setObjectName("mesher");
  ui.mesher->addItems({tr("TetGen (conforming Delaunay)"), tr("CGAL Mesh_3 (regular)")});
  form->addRow(tr("Mesher"), ui.mesher);
  ui.max_size = new QLineEdit;
  ui.max_size->setObjectName("mesh_size");
  ui.max_size->setToolTip(
      tr("target edge length everywhere (\"0.5 mm\"; a bare number is in the model's "
         "length unit); empty: the model's [mesh] max_size"));
  form->addRow(tr("Size"), ui.max_size);
  ui.quality = new QLineEdit;
  ui.quality->setObjectName("mesh_quality");
  ui.quality->setToolTip(
      tr("radius-edge bound: TetGen 0 (none) or at least 1.414; CGAL's cell bound "
         "(2 or more guarantees termination); empty: the default"));
  form->addRow(tr("Quality"), ui.quality);
  mv->addLayout(form);
  ui.parts = settings_table("part_sizes", {tr("part"), tr("size"), tr("model's")});
  ui.parts->horizontalHeader()->setStretchLastSection(true);
  mv->addWidget(new QLabel(tr("Part sizes (empty: the model's)")));
  mv->addWidget(ui.parts);
  auto* box_row = new QHBoxLayout;
  box_row->addWidget(new QLabel(tr("Refinement boxes")), 1);
  auto* add_box = new QPushButton(tr("Add"));
  auto* remove_box = new QPushButton(tr("Remove"));
  add_box->setObjectName("add_box");
  remove_box->setObjectName("remove_box");
  box_row->addWidget(add_box);
  box_row->addWidget(remove_box);
  mv->addLayout(box_row);
  QStringList columns;
  for (const char* c : kBoxColumns) columns << c;
  ui.boxes = settings_table("refine_boxes", columns);
  ui.boxes->setToolTip(
      tr("target edge length `size` inside each box (corners and size in the model's length unit); TetGen's "
         "size field, or CGAL's cell and facet sizes (the regular tet's circumradius)"));
  ui.boxes->horizontalHeader()->setSectionResizeMode(QHeaderView::Stretch);
  ui.boxes->setFixedHeight(ui.boxes->horizontalHeader()->sizeHint().height() + 2 * 20 + 4);
  mv->addWidget(ui.boxes);
  auto* refine_row = new QHBoxLayout;
  ui.refine = new QCheckBox(tr("Refine from the result (TetGen)"));
  ui.refine->setObjectName("refine_from_result");
  ui.refine->setToolTip(
      tr("the next mesh's sizes from the Zienkiewicz-Zhu error of the result's field (TetGen)"));
  ui.refine_field = new QComboBox;
  ui.target_error = new QLineEdit;
  ui.target_error->setObjectName("target_error");
  ui.target_error->setToolTip(tr("relative gradient error aimed at (e.g. 0.05)"));
  ui.target_error->setMaximumWidth(60);
  mv->addWidget(ui.refine);
  refine_row->addWidget(new QLabel(tr("field")));
  refine_row->addWidget(ui.refine_field, 1);
  refine_row->addWidget(new QLabel(tr("target error")));
  refine_row->addWidget(ui.target_error);
  mv->addLayout(refine_row);
  ui.error = new QLabel;
  ui.error->setObjectName("mesh_settings_error");
  ui.error->setWordWrap(true);
  ui.error->setStyleSheet("color: #b00000");
  mv->addWidget(ui.error);
  auto edited = [this] { on_mesh_controls_edited(); };
  connect(ui.mesher, qOverload<int>(&QComboBox::currentIndexChanged), this, edited);
  connect(ui.max_size, &QLineEdit::editingFinished, this, edited);
  connect(ui.quality, &QLineEdit::editingFinished, this, edited);
  connect(ui.target_error, &QLineEdit::editingFinished, this, edited);
  connect(ui.parts, &QTableWidget::cellChanged, this, edited);
  connect(ui.boxes, &QTableWidget::cellChanged, this, edited);
  connect(ui.refine, &QCheckBox::toggled, this, edited);
  connect(ui.refine_field, qOverload<int>(&QComboBox::activated), this, edited);
  // A new box: the shown mesh's bounds (the model's length unit) with a tenth of its diagonal.
  connect(add_box, &QPushButton::clicked, this, [this] {
    MeshSettings s = mesh_settings_;
    RefinementBox b;
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = bounds_lo_[k];
      b.hi[k] = bounds_hi_[k];
      d2 += (b.hi[k] - b.lo[k]) * (b.hi[k] - b.lo[k]);
    }
    b.size = d2 > 0 ? std::sqrt(d2) / 10 : (model_ ? model_->length_scale : 1);
    if (!(d2 > 0))
      for (int k = 0; k < 3; ++k) b.hi[k] = model_ ? model_->length_scale : 1;
    s.boxes.push_back(b);
    set_mesh_settings(s);
  });
  connect(remove_box, &QPushButton::clicked, this, [this] {
    MeshSettings s = mesh_settings_;
    if (s.boxes.empty()) return;
    const int row = mesh_ui_->boxes->currentRow();
    s.boxes.erase(s.boxes.begin() + (row >= 0 && row < int(s.boxes.size()) ? row : int(s.boxes.size()) - 1));
    set_mesh_settings(s);
  });

  // The mesh's quality report and its dihedral-angle histogram.
  quality_text_ = new QPlainTextEdit;
  quality_text_->setObjectName("quality_report");
  quality_text_->setReadOnly(true);
  quality_text_->setLineWrapMode(QPlainTextEdit::NoWrap);
  histogram_ = new QLabel;
  mv->addWidget(histogram_);
  mv->addWidget(quality_text_, 1);
  mesh_panel->setMinimumWidth(320);
  // In a scroll area: the panel's natural height is most of the window's, and the results dock below
  // it would get what is left (one row of the results table at 860 px). Scrolled, the two share the
  // height (build_ui splits it; the user moves the line between them).
  auto* scroll = new QScrollArea;
  scroll->setObjectName("mesh_scroll");
  scroll->setWidget(mesh_panel);
  scroll->setWidgetResizable(true);
  scroll->setFrameShape(QFrame::NoFrame);
  scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  auto* mesh_dock = new QDockWidget(tr("Mesh"));
  mesh_dock->setObjectName("mesh");
  mesh_dock->setWidget(scroll);
  addDockWidget(Qt::RightDockWidgetArea, mesh_dock);
  refresh_mesh_controls();
}

}  // namespace foxi::workbench
