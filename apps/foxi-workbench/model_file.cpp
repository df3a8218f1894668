// foxi-workbench's model file row (Save model, Save model as) and the model panel's exploded parts
// picture, both on the libraries' calls: save_model (structure) and draw_model_picture (viz), the
// calls foxi model show uses, so that the panel shows foxi model show's picture.
#include <QFileDialog>
#include <QFileInfo>
#include <QHBoxLayout>
#include <QLabel>
#include <QPixmap>
#include <QPushButton>
#include <QSettings>
#include <QtConcurrent>

#include "foxi/mesher/model_mesh.hpp"
#include "foxi/model/model_save.hpp"
#include "foxi/viz/model_picture.hpp"
#include "workbench.hpp"
#include "workbench_parts.hpp"

namespace foxi::workbench {

QHBoxLayout* Workbench::build_model_file_row() {
  auto* row = new QHBoxLayout;
  auto* save = new QPushButton(tr("Save model"));
  save->setObjectName("save_model");
  save->setToolTip(tr("Write the parameter values into the model file (Ctrl+Shift+S)"));
  auto* save_as = new QPushButton(tr("Save model as..."));
  save_as->setObjectName("save_model_as");
  connect(save, &QPushButton::clicked, this, [this] { save_model_file(); });
  connect(save_as, &QPushButton::clicked, this, [this] {
    if (model_path_.isEmpty()) return;
    const QString f =
        QFileDialog::getSaveFileName(this, tr("Save the model as"), model_path_, tr("Models (*.toml)"));
    if (!f.isEmpty() && save_model_file(f)) QSettings().setValue("last_model", f);
  });
  row->addWidget(save);
  row->addWidget(save_as);
  return row;
}

bool Workbench::save_model_file(const QString& path, QString* error) {
  if (model_path_.isEmpty()) {
    if (error) *error = tr("no model is open");
    return false;
  }
  const QString target = path.isEmpty() ? model_path_ : path;
  try {
    const std::vector<ParameterOverride> values = overrides();
    // The shown mesh is of these values (the open file with them): it stays the current mesh, of the
    // saved file with no overrides, so that the next Solve does not remesh the same geometry.
    const bool current = mesh_ && meshed_path_ == model_path_ && same_overrides(values, meshed_overrides_);
    save_model(model_path_.toStdString(), target.toStdString(), values);
    // The saved file holds the values: the workbench goes on with it and no overrides (the edits
    // before it are the file's now, so they are not undone past the save)
    if (!open_model(target, error)) {
      meshed_path_.clear();
      return false;
    }
    if (current) {
      meshed_path_ = target;
      meshed_overrides_.clear();
      meshed_model_ = model_;
    } else {
      meshed_path_.clear();  // of other values: the next Solve remeshes
    }
    changed();
    return true;
  } catch (const std::exception& e) {
    show_error(what_of(e));
    if (error) *error = what_of(e);
    return false;
  }
}

QImage Workbench::parts_picture(const QString& model, const std::vector<ParameterOverride>& overrides,
                                int width, int height, QString* error) {
  try {
    ModelMeshOptions options;
    options.coarse = true;  // foxi model show's mesh
    const MeshedModel m = mesh_model(model.toStdString(), overrides, options);
    const ModelScene scene(m.mesh, ModelView::exploded);
    Framebuffer fb(width, height);
    draw_model_picture(scene, model_region_colors(m.mesh), fb);
    // pack_rgba is R, G, B, A in memory order: QImage's RGBA8888 (copied: fb goes)
    return QImage(reinterpret_cast<const uchar*>(fb.rgba.data()), fb.width, fb.height, fb.width * 4,
                  QImage::Format_RGBA8888)
        .copy();
  } catch (const std::exception& e) {
    if (error) *error = what_of(e);
    return {};
  }
}

QLabel* Workbench::build_parts_picture() {
  parts_label_ = new QLabel;
  parts_label_->setObjectName("parts_picture");
  parts_label_->setAlignment(Qt::AlignCenter);
  parts_label_->setMinimumSize(160, 120);
  parts_label_->setToolTip(tr("The parts, exploded (foxi model show)"));
  return parts_label_;
}

void Workbench::refresh_parts_picture() {
  if (!parts_label_ || !model_) return;
  QString key = model_path_;
  for (const auto& [n, e] : overrides_) key += "\n" + QString::fromStdString(n + "=" + e);
  if (key == parts_key_) return;  // a refused edit redraws the table, not the parts
  parts_key_ = key;
  const std::size_t serial = ++parts_serial_;
  // drawn at device pixels (high-DPI: the label's size times its ratio, not a scaled-up picture)
  const qreal ratio = parts_label_->devicePixelRatioF();
  // the label's whole area (a picture taller than the label would be cut off at the bottom)
  const int w = std::max(160, int(parts_label_->width() * ratio)),
            h = std::max(120, int(parts_label_->height() * ratio));
  auto* watcher = new QFutureWatcher<QImage>(this);
  connect(watcher, &QFutureWatcher<QImage>::finished, this, [this, watcher, serial, ratio] {
    watcher->deleteLater();
    if (serial != parts_serial_) return;  // a newer request is on its way
    parts_image_ = watcher->result();
    ++parts_pictures_;
    QPixmap pixmap = QPixmap::fromImage(parts_image_);
    pixmap.setDevicePixelRatio(ratio);
    parts_label_->setPixmap(pixmap);
  });
  watcher->setFuture(QtConcurrent::run(
      [model = model_path_, values = overrides(), w, h] { return parts_picture(model, values, w, h); }));
}

}  // namespace foxi::workbench
