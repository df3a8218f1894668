// The Xlib event loop of foxi-view (see x11_window.hpp). Kept thin: every action is a call on the
// Viewer; this file only moves pixels to the screen and turns events into those calls.
#include "x11_window.hpp"

#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/extensions/XShm.h>
#include <X11/keysym.h>
#include <sys/ipc.h>
#include <sys/select.h>
#include <sys/shm.h>

#include <algorithm>
#include <chrono>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <stdexcept>

namespace foxi::view {

namespace {

constexpr int kStatusHeight = 18;

bool g_x_error = false;
int record_error(Display*, XErrorEvent*) {
  g_x_error = true;
  return 0;
}

int shift_of(unsigned long mask) {
  int s = 0;
  while (mask && !(mask & 1)) {
    mask >>= 1;
    ++s;
  }
  return s;
}

// An XImage of the picture, in shared memory when possible.
class Screen {
 public:
  Screen(Display* dpy, Visual* visual, int depth) : dpy_(dpy), visual_(visual), depth_(depth) {
    int major = 0, minor = 0;
    Bool pixmaps = False;
    use_shm_ = XShmQueryExtension(dpy_) && XShmQueryVersion(dpy_, &major, &minor, &pixmaps);
    if (std::getenv("FOXI_VIEW_NO_SHM")) use_shm_ = false;
    rs_ = shift_of(visual_->red_mask);
    gs_ = shift_of(visual_->green_mask);
    bs_ = shift_of(visual_->blue_mask);
  }
  ~Screen() { release(); }
  bool shm() const { return use_shm_; }

  void ensure(int w, int h) {
    if (image_ && w == w_ && h == h_) return;
    release();
    w_ = w;
    h_ = h;
    if (use_shm_) {
      image_ = XShmCreateImage(dpy_, visual_, unsigned(depth_), ZPixmap, nullptr, &shm_info_, unsigned(w),
                               unsigned(h));
      if (image_) {
        shm_info_.shmid =
            shmget(IPC_PRIVATE, std::size_t(image_->bytes_per_line) * std::size_t(h), IPC_CREAT | 0600);
        if (shm_info_.shmid >= 0) {
          shm_info_.shmaddr = image_->data = static_cast<char*>(shmat(shm_info_.shmid, nullptr, 0));
          shm_info_.readOnly = False;
          g_x_error = false;
          auto old = XSetErrorHandler(record_error);
          XShmAttach(dpy_, &shm_info_);
          XSync(dpy_, False);
          XSetErrorHandler(old);
          shmctl(shm_info_.shmid, IPC_RMID, nullptr);  // freed once both sides detach
          if (!g_x_error) {
            attached_ = true;
            return;
          }
          shmdt(shm_info_.shmaddr);
        }
        image_->data = nullptr;
        XDestroyImage(image_);
        image_ = nullptr;
      }
      use_shm_ = false;  // e.g. a remote display: fall back for good
    }
    image_ =
        XCreateImage(dpy_, visual_, unsigned(depth_), ZPixmap, 0, nullptr, unsigned(w), unsigned(h), 32, 0);
    if (!image_) throw std::runtime_error("XCreateImage failed");
    image_->data = static_cast<char*>(std::calloc(std::size_t(image_->bytes_per_line) * std::size_t(h), 1));
  }

  // Shows the rectangle `rect` of fb (all of it when the image is new); an empty rect shows nothing.
  void put(Window win, GC gc, const Framebuffer& fb, PixelRect rect) {
    if (!image_ || w_ != fb.width || h_ != fb.height) rect = PixelRect{0, 0, fb.width - 1, fb.height - 1};
    ensure(fb.width, fb.height);
    rect.x0 = std::max(rect.x0, 0);
    rect.y0 = std::max(rect.y0, 0);
    rect.x1 = std::min(rect.x1, fb.width - 1);
    rect.y1 = std::min(rect.y1, fb.height - 1);
    if (rect.x0 > rect.x1 || rect.y0 > rect.y1) return;
    for (int y = rect.y0; y <= rect.y1; ++y) {
      const std::uint32_t* src = fb.rgba.data() + fb.index(0, y);
      // The fast path writes host-order words: right when the image is 32-bit and in our byte order.
      if (image_->bits_per_pixel == 32 &&
          image_->byte_order == (std::endian::native == std::endian::little ? LSBFirst : MSBFirst)) {
        auto* dst = reinterpret_cast<std::uint32_t*>(image_->data +
                                                     std::size_t(y) * std::size_t(image_->bytes_per_line));
        for (int x = rect.x0; x <= rect.x1; ++x) {
          std::uint32_t p = src[x];
          dst[x] = (p & 255u) << rs_ | (p >> 8 & 255u) << gs_ | (p >> 16 & 255u) << bs_;
        }
      } else {
        for (int x = rect.x0; x <= rect.x1; ++x) {
          std::uint32_t p = src[x];
          XPutPixel(image_, x, y, (p & 255u) << rs_ | (p >> 8 & 255u) << gs_ | (p >> 16 & 255u) << bs_);
        }
      }
    }
    const unsigned w = unsigned(rect.x1 - rect.x0 + 1), h = unsigned(rect.y1 - rect.y0 + 1);
    if (attached_)
      XShmPutImage(dpy_, win, gc, image_, rect.x0, rect.y0, rect.x0, rect.y0, w, h, False);
    else
      XPutImage(dpy_, win, gc, image_, rect.x0, rect.y0, rect.x0, rect.y0, w, h);
  }

 private:
  void release() {
    if (!image_) return;
    if (attached_) {
      XShmDetach(dpy_, &shm_info_);
      XSync(dpy_, False);
      shmdt(shm_info_.shmaddr);
      image_->data = nullptr;
      attached_ = false;
    }
    XDestroyImage(image_);  // frees calloc'd data in the plain case
    image_ = nullptr;
  }

  Display* dpy_;
  Visual* visual_;
  int depth_;
  bool use_shm_ = false, attached_ = false;
  XShmSegmentInfo shm_info_{};
  XImage* image_ = nullptr;
  int w_ = 0, h_ = 0, rs_ = 16, gs_ = 8, bs_ = 0;
};

}  // namespace

int run_window(Viewer& viewer, ViewField& field, const std::string& save_prefix) {
  Display* dpy = XOpenDisplay(nullptr);
  if (!dpy)
    throw std::runtime_error("cannot open the X display (DISPLAY unset?); --script runs without a window");
  const int scr = DefaultScreen(dpy);
  XVisualInfo vinfo;
  if (!XMatchVisualInfo(dpy, scr, 24, TrueColor, &vinfo) &&
      !XMatchVisualInfo(dpy, scr, 32, TrueColor, &vinfo)) {
    XCloseDisplay(dpy);
    throw std::runtime_error("the X display has no 24-bit TrueColor visual");
  }
  int width = viewer.framebuffer().width, height = viewer.framebuffer().height;
  XSetWindowAttributes attrs{};
  attrs.colormap = XCreateColormap(dpy, RootWindow(dpy, scr), vinfo.visual, AllocNone);
  attrs.background_pixel = 0;
  attrs.border_pixel = 0;
  attrs.event_mask = ExposureMask | KeyPressMask | ButtonPressMask | ButtonReleaseMask | PointerMotionMask |
                     StructureNotifyMask;
  Window win = XCreateWindow(dpy, RootWindow(dpy, scr), 0, 0, unsigned(width),
                             unsigned(height + kStatusHeight), 0, vinfo.depth, InputOutput, vinfo.visual,
                             CWColormap | CWBackPixel | CWBorderPixel | CWEventMask, &attrs);
  XStoreName(dpy, win, "foxi-view");
  Atom wm_delete = XInternAtom(dpy, "WM_DELETE_WINDOW", False);
  XSetWMProtocols(dpy, win, &wm_delete, 1);
  XMapWindow(dpy, win);
  GC gc = XCreateGC(dpy, win, 0, nullptr);
  XFontStruct* font = XLoadQueryFont(dpy, "fixed");
  if (font) XSetFont(dpy, gc, font->fid);
  const unsigned long white = (vinfo.red_mask | vinfo.green_mask | vinfo.blue_mask);
  const unsigned long grey = ((vinfo.red_mask / 255 * 40) & vinfo.red_mask) |
                             ((vinfo.green_mask / 255 * 40) & vinfo.green_mask) |
                             ((vinfo.blue_mask / 255 * 40) & vinfo.blue_mask);
  std::optional<Screen> screen_holder;
  screen_holder.emplace(dpy, vinfo.visual, vinfo.depth);
  Screen& screen = *screen_holder;

  std::printf(
      "foxi-view: %zu tets, %s, %s; keys: d draw, space stop/continue, n step, u undraw/draw on, r region, "
      "b back, f field, m colour map, l legend, i isosurface, o solid/surface, [ ] isovalue, s save, "
      "q quit; mouse: left orbit, right/wheel zoom, middle pan\n",
      viewer.mesh().tet_count(),
      viewer.delaunay() ? "Delaunay (painter, no depth buffer)" : "NOT Delaunay (depth-buffer drawing)",
      screen.shm() ? "XShm" : "XPutImage");
  std::fflush(stdout);

  int mouse_x = -1, mouse_y = -1;  // the pointer over the picture (-1: elsewhere)
  auto draw_status = [&] {
    XSetForeground(dpy, gc, grey);
    XFillRectangle(dpy, win, gc, 0, height, unsigned(width), kStatusHeight);
    XSetForeground(dpy, gc, white);
    std::string s = viewer.status();
    const std::string fs = field_status(field);
    if (!fs.empty()) s += "  |  " + fs;
    if (mouse_x >= 0) s += "  |  " + value_under(viewer, field, mouse_x, mouse_y);
    const int base = height + kStatusHeight - 5;
    XDrawString(dpy, win, gc, 4, base, s.c_str(), int(s.size()));
  };
  bool exposed = true;  // the whole picture must be shown again (exposed or resized window)
  auto show = [&] {
    // Only what changed since the last show, unless the window needs all of it.
    const Framebuffer& fb = viewer.framebuffer();
    const std::vector<PixelRect> damage = viewer.take_damage();
    if (field.legend) {  // the scene beside the legend, put whole
      const Framebuffer shown = presented(viewer, field);
      screen.put(win, gc, shown, PixelRect{0, 0, shown.width - 1, shown.height - 1});
    } else if (exposed)
      screen.put(win, gc, fb, PixelRect{0, 0, fb.width - 1, fb.height - 1});
    else
      for (const PixelRect& rect : damage) screen.put(win, gc, fb, rect);
    exposed = false;
    draw_status();
    XSync(dpy, False);  // the server has read the shared image before the next batch changes it
  };
  auto report_done = [&] {
    std::printf("done %s\n", viewer.status().c_str());
    std::fflush(stdout);
  };

  viewer.set_running(true);
  viewer.restart();
  bool quit = false, mapped = false;
  std::size_t reported = 0;  // the generation whose completion was last reported
  bool was_done = false, was_undrawn = false;
  int button = 0, last_x = 0, last_y = 0;
  while (!quit) {
    bool changed = false;
    // Every queued event first, so the window stays responsive between batches.
    while (!quit && XPending(dpy) > 0) {
      XEvent ev;
      XNextEvent(dpy, &ev);
      switch (ev.type) {
        case MapNotify:
          mapped = true;
          break;
        case Expose:
          if (ev.xexpose.count == 0) changed = exposed = true;
          break;
        case ConfigureNotify: {
          int w = ev.xconfigure.width, h = ev.xconfigure.height - kStatusHeight;
          if (w > 0 && h > 0 && (w != width || h != height)) {
            width = w;
            height = h;
            field.full_width = w;
            resize_view(viewer, field, field.legend ? w - field.panel : w, h);
            viewer.set_running(true);
            changed = exposed = true;
          }
          break;
        }
        case ClientMessage:
          if (Atom(ev.xclient.data.l[0]) == wm_delete) quit = true;
          break;
        case ButtonPress: {
          const int b = int(ev.xbutton.button);
          if (b == 4 || b == 5) {
            viewer.zoom(b == 4 ? 1.1 : 1 / 1.1);
            viewer.set_running(true);
            changed = true;
          } else {
            button = b;
            last_x = ev.xbutton.x;
            last_y = ev.xbutton.y;
          }
          break;
        }
        case ButtonRelease:
          if (int(ev.xbutton.button) == button) button = 0;
          break;
        case MotionNotify: {
          if (!button) {  // the value under the mouse on the status line
            while (XCheckTypedWindowEvent(dpy, win, MotionNotify, &ev)) {
            }
            const bool inside = ev.xmotion.x >= 0 && ev.xmotion.y >= 0 &&
                                ev.xmotion.x < viewer.framebuffer().width && ev.xmotion.y < height;
            mouse_x = inside ? ev.xmotion.x : -1;
            mouse_y = inside ? ev.xmotion.y : -1;
            changed = true;
            break;
          }
          while (XCheckTypedWindowEvent(dpy, win, MotionNotify, &ev)) {
          }  // only the latest position matters
          const int dx = ev.xmotion.x - last_x, dy = ev.xmotion.y - last_y;
          last_x = ev.xmotion.x;
          last_y = ev.xmotion.y;
          if (dx == 0 && dy == 0) break;
          if (button == 1)
            viewer.orbit(-0.4 * dx, -0.4 * dy);
          else if (button == 3)
            viewer.zoom(std::exp(-0.01 * dy));
          else if (button == 2)
            viewer.pan(-double(dx) / height, double(dy) / height);
          viewer.set_running(true);
          changed = true;
          break;
        }
        case KeyPress: {
          char text[8] = {};
          KeySym sym = 0;
          XLookupString(&ev.xkey, text, sizeof text - 1, &sym, nullptr);
          switch (sym) {
            case XK_q:
            case XK_Q:
            case XK_Escape:
              quit = true;
              break;
            case XK_d:
              viewer.restart();
              viewer.set_running(true);
              break;
            case XK_u:
              if (viewer.set_undrawing(!viewer.undrawing())) viewer.set_running(true);
              break;
            case XK_space:
              viewer.set_running(!viewer.running());
              break;
            case XK_n:
              viewer.set_running(false);
              viewer.step();
              break;
            case XK_r:
              if (viewer.push_region())
                viewer.set_running(true);
              else if (viewer.translucent())
                std::fprintf(stderr,
                             "foxi-view: r (a region of interest) is refused while the x-ray or translucent "
                             "isosurfaces are on: turn them off first\n");
              break;
            case XK_b:
              if (viewer.pop_region()) viewer.set_running(true);
              break;
            case XK_f:
              next_field(viewer, field);
              viewer.set_running(true);
              break;
            case XK_m:
              next_map(viewer, field);
              viewer.set_running(true);
              break;
            case XK_l:
              try {
                if (toggle_legend(viewer, field)) {
                  viewer.set_running(true);
                  exposed = true;
                }
              } catch (const std::exception& e) {
                std::fprintf(stderr, "foxi-view: no legend: %s\n", e.what());
              }
              break;
            case XK_i:
              toggle_iso(viewer, field);
              viewer.set_running(true);
              break;
            case XK_o:
              toggle_iso_only(viewer, field);
              viewer.set_running(true);
              break;
            case XK_bracketleft:
            case XK_bracketright:
              move_iso(viewer, field, sym == XK_bracketright ? 1 : -1);
              viewer.set_running(true);
              break;
            case XK_x:
            case XK_t:
            case XK_v:
              try {
                if (sym == XK_x   ? toggle_xray(viewer, field)
                    : sym == XK_t ? toggle_iso_translucent(viewer, field)
                                  : toggle_volume(viewer, field))
                  viewer.set_running(true);
              } catch (const std::exception& e) {
                std::fprintf(stderr, "foxi-view: %s\n", e.what());
              }
              break;
            case XK_s:
              try {
                save_next(viewer, save_prefix, false, &field);
              } catch (const std::exception& e) {
                std::fprintf(stderr, "foxi-view: %s\n", e.what());
              }
              break;
            default:
              break;
          }
          changed = true;
          break;
        }
        default:
          break;
      }
    }
    if (quit) break;
    if (viewer.running() && mapped) {
      // Compositing resolves the whole picture when it is shown (interactive_view.hpp): batches for
      // up to 40 ms between two showings, so a 1M-tet volume is not a resolve per batch.
      if (viewer.translucent() || viewer.volume())
        viewer.step(std::chrono::milliseconds(40));
      else
        viewer.step();
      changed = true;
    }
    // "done" once per completed draw (again after an undraw and a draw on), "undrawn" once per
    // complete undraw.
    if (viewer.done() && (reported != viewer.generation() || !was_done)) {
      reported = viewer.generation();
      report_done();
      changed = true;
    }
    was_done = viewer.done();
    const bool undrawn = viewer.undrawing() && viewer.drawn().empty();
    if (undrawn && !was_undrawn) {
      std::printf("undrawn %s\n", viewer.status().c_str());
      std::fflush(stdout);
      changed = true;
    }
    was_undrawn = undrawn;
    if (changed && mapped) show();
    if (!viewer.running() || !mapped) {
      // Idle: sleep until the next event.
      const int fd = ConnectionNumber(dpy);
      fd_set fds;
      FD_ZERO(&fds);
      FD_SET(fd, &fds);
      timeval tv{0, 200000};
      if (XPending(dpy) == 0) select(fd + 1, &fds, nullptr, nullptr, &tv);
    }
  }
  if (font) XFreeFont(dpy, font);
  XFreeGC(dpy, gc);
  XDestroyWindow(dpy, win);
  screen_holder.reset();  // detaches the shared memory while the display is open
  XFreeColormap(dpy, attrs.colormap);
  XCloseDisplay(dpy);
  return 0;
}

}  // namespace foxi::view
