// qt_window: a minimal Qt5 host embedding foxi's view widget.
//
//   qt_window MODEL.toml [--save VIEW.png]
//
// Meshes the model file (foxi::mesh_model: a certified Delaunay mesh) and shows it in a
// foxi::qt::ViewWidget inside the host's own window: drag to orbit (middle: pan, wheel: zoom), the
// buttons draw, stop, step and undraw, the slider sets the fraction drawn. With --save the host
// draws the picture to completion, saves the widget's framebuffer as a PNG and quits (run it with
// QT_QPA_PLATFORM=offscreen where there is no display).
#include <QApplication>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QSlider>
#include <QVBoxLayout>
#include <QWidget>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>

#include "foxi/mesher.hpp"
#include "foxi/qt.hpp"

int main(int argc, char** argv) {
  QApplication app(argc, argv);
  if (argc != 2 && !(argc == 4 && std::string(argv[2]) == "--save")) {
    std::fprintf(stderr, "usage: qt_window MODEL.toml [--save VIEW.png]\n");
    return 2;
  }
  std::shared_ptr<foxi::Mesh> mesh;
  try {
    mesh = std::make_shared<foxi::Mesh>(foxi::mesh_model(argv[1]).mesh);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "qt_window: %s\n", e.what());
    return 1;
  }

  QWidget window;
  auto* layout = new QVBoxLayout(&window);
  auto* bar = new QHBoxLayout;
  auto* view = new foxi::qt::ViewWidget;
  view->setMinimumSize(640, 480);
  for (auto [text, slot] :
       {std::pair{"Draw", &foxi::qt::ViewWidget::draw}, std::pair{"Stop", &foxi::qt::ViewWidget::stop},
        std::pair{"Step", &foxi::qt::ViewWidget::step_once},
        std::pair{"Undraw", &foxi::qt::ViewWidget::undraw}}) {
    auto* b = new QPushButton(text);
    QObject::connect(b, &QPushButton::clicked, view, slot);
    bar->addWidget(b);
  }
  auto* slider = new QSlider(Qt::Horizontal);
  slider->setRange(0, 100);
  slider->setValue(100);
  QObject::connect(slider, &QSlider::sliderMoved, view, [view](int v) { view->set_fraction(v / 100.0); });
  bar->addWidget(slider, 1);
  auto* status = new QLabel;
  QObject::connect(view, &foxi::qt::ViewWidget::status_changed, status, &QLabel::setText);
  layout->addLayout(bar);
  layout->addWidget(view, 1);
  layout->addWidget(status);
  window.setWindowTitle("foxi view in a host window");
  window.show();
  QApplication::processEvents();  // laid out: the view has its size

  foxi::RenderParams params;
  params.undoable = true;  // the Undraw button and the slider take tets back
  view->set_mesh(mesh, params);
  if (argc == 4) {
    view->finish_now();
    QString error;
    if (!view->save_picture(argv[3], &error)) {
      std::fprintf(stderr, "qt_window: %s\n", error.toUtf8().constData());
      return 1;
    }
    std::printf("qt_window: %s: %zu tets; %s\n", argv[3], mesh->tet_count(),
                view->status_text().toUtf8().constData());
    return 0;
  }
  return app.exec();
}
