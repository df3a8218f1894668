// foxi-workbench's mesh panel: the quality report and its dihedral-angle histogram.
#include "workbench.hpp"
#include "workbench_parts.hpp"

#include <QDockWidget>
#include <QImage>
#include <QLabel>
#include <QPainter>
#include <QPlainTextEdit>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>

namespace foxi::workbench {

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

void Workbench::build_mesh_panel() {
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
}

}  // namespace foxi::workbench
