// foxi-view's headless script mode on the interactive view (foxi/viz/interactive_view.hpp, the
// window-free core the Xlib front end (x11_window.cpp) drives as well), and the picture saving both
// share.
#pragma once

#include <filesystem>
#include <string>

#include "foxi/viz/interactive_view.hpp"

namespace foxi::view {

using Viewer = InteractiveView;

// Runs a script of whitespace-separated commands on the viewer (the headless mode):
//   d            restart and draw to completion      c      restart without drawing
//   n            draw one batch                      f      finish the current draw
//   r / b        push the drawn tets as region / back up   (each restarts without drawing)
//   orbit:Y,P    orbit by yaw, pitch degrees         zoom:F  zoom by F       pan:X,Y  pan
//   s            save the picture as PREFIX-NNN.png (and with dump, PREFIX-NNN.ids: the id buffer as
//                little-endian uint32, and PREFIX-NNN.tets: the drawn tets, one a line)
// Prints one line per save ("saved NAME ...") on stdout. Throws std::invalid_argument on a bad command.
void run_script(Viewer& viewer, const std::string& script, const std::string& prefix, bool dump);

// Saves the picture under the next free name PREFIX-NNN.png; prints "saved NAME camera ..." and
// returns the path. With dump, also writes the id buffer and the drawn tets beside it.
std::filesystem::path save_next(const Viewer& viewer, const std::string& prefix, bool dump);

}  // namespace foxi::view
