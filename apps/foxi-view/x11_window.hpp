// The Xlib front end of foxi-view: a window showing the viewer's framebuffer (XShm where the server
// has it, plain XPutImage otherwise) with a status line, mouse and keys driving the viewer.
#pragma once

#include <string>

#include "viewer.hpp"

namespace foxi::view {

// Opens the window and runs the event loop until q / Escape / the window is closed. Returns the exit
// status; throws std::runtime_error if the display cannot be opened.
// `field`: the colouring (keys f and m change it); the status line shows the value under the mouse.
int run_window(Viewer& viewer, ViewField& field, const std::string& save_prefix);

}  // namespace foxi::view
