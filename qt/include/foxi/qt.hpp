// foxi::qt, the Qt5 view widget (link foxi::qt; needs Qt5 Widgets), in one include:
//   ViewWidget   a QWidget drawing a mesh progressively with the painter: orbit/pan/zoom, draw,
//                stop, step, undraw, the fraction drawn, regions of interest, the value under the
//                mouse, save the picture (foxi/qt/view_widget.hpp)
//   make_view    the InteractiveView a widget shows, built on any thread (foxi/qt/view_widget.hpp)
#pragma once

#include "foxi/qt/view_widget.hpp"
#include "foxi/viz/interactive_view.hpp"
#include "foxi/viz/rasterizer.hpp"
