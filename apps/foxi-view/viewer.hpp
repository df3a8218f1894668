// foxi-view's headless script mode on the interactive view (foxi/viz/interactive_view.hpp, the
// window-free core the Xlib front end (x11_window.cpp) drives as well), and the picture saving both
// share.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "foxi/viz/colormap.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/interactive_view.hpp"
#include "foxi/viz/isosurface.hpp"
#include "foxi/viz/legend.hpp"
#include "foxi/viz/text.hpp"
#include "foxi/viz/translucent.hpp"
#include "foxi/viz/view_options.hpp"
#include "foxi/viz/volume.hpp"

namespace foxi::view {

using Viewer = InteractiveView;

// The field the view is coloured by (--field, --graded, --cmap; keys f and m) and what the status
// line says under the mouse.
struct ViewField {
  std::vector<std::string> specs;  // "" (region colours), then each field of the mesh by name
  std::size_t current = 0;         // index into specs
  ColorMapId map = ColorMapId::viridis;
  bool graded = false;
  // Resolved by apply_field for specs[current] (its last step), when that is not "":
  FieldChoice choice;
  std::size_t step = 0;
  ColorScale scale;
  DisplayUnit unit;
  // scale is the range of the tets' corner values (graded, and for the volume and translucent
  // isosurfaces, which show the field between the nodes: foxi render's rule), else of their centroids'.
  bool scale_of_corners = false;
  std::size_t no_value = 0;  // of those values, the NaN ones
  // The isosurface (keys i, o, [ and ]): at iso_value (SI), the solid above it or (iso_only) the surface.
  bool iso_on = false, iso_only = false;
  double iso_value = 0;
  std::vector<double> corner;  // the field's corner values (the IsoPainter's, lent to the view)
  std::shared_ptr<const TetIntervals> tree;
  IsoDrawing drawing;
  // The legend (key l): a panel of `panel` pixels at the right of a picture `full_width` wide, the
  // scene narrowed by it (the camera kept).
  bool legend = false;
  int panel = 0, full_width = 0;
  std::shared_ptr<const TextRenderer> text;
  // Compositing (issue 23; keys x, t, v): translucent regions ("x-ray"), translucent nested
  // isosurfaces of the field, or a volume rendering of the field, composited in the power order.
  bool xray = false;                        // key x
  std::vector<RegionOpacity> xray_regions;  // --region-opacity; empty: default_xray (interactive_view.hpp)
  bool iso_translucent = false;             // key t: iso_count isosurfaces across the range
  int iso_count = 5;
  double iso_opacity = 0.35;        // --iso-opacity
  bool volume = false;              // key v (or --volume at the start)
  std::vector<OpacityPoint> curve;  // --opacity-curve (display units); empty: a ramp
  TranslucentParams translucent;    // what the view was given (its corner: `corner` above)
  VolumeParams volume_params;
  // The camera as fitted from the options (camera_for) to the mesh box [box_lo, box_hi]: while the
  // view still has it (not orbited, zoomed or panned), a new width (the legend's panel, a resized
  // window) fits it again, as foxi render fits its camera to what the legend leaves.
  CameraOptions camera_options;
  double box_lo[3] = {0, 0, 0}, box_hi[3] = {0, 0, 0};
  std::optional<Camera> fitted;
};

// The view's size changed to width x height: the camera fitted again where the user has not moved
// it (ViewField::fitted), then the view resized.
void resize_view(Viewer& viewer, ViewField& field, int width, int height);

// The specs of `mesh` ("" and its fields' names), `current` set to `spec` (NAME[:component], added
// if it names a component); std::invalid_argument (FieldSelectError) for a field not in the mesh.
ViewField view_field(const Mesh& mesh, const std::string& spec, bool graded, ColorMapId map);
// Colours the viewer by field.specs[field.current] (its automatic range, the display unit an
// engineer reads it in) and restarts the draw.
void apply_field(Viewer& viewer, ViewField& field);
// 'f': the next field (after the last, region colours again); 'm': the next colour map.
void next_field(Viewer& viewer, ViewField& field);
void next_map(Viewer& viewer, ViewField& field);
// The isosurface at `value` (display units) of the current field, drawn as the solid above it or
// (iso_only) the surface alone; false (nothing changes) with region colours.
bool set_iso(Viewer& viewer, ViewField& field, double value, bool iso_only);
// 'i': the isosurface on (at the middle of the range) or off; 'o': solid / surface alone;
// '[' and ']': the isovalue down or up by 1/20 of the colour range.
void toggle_iso(Viewer& viewer, ViewField& field);
void toggle_iso_only(Viewer& viewer, ViewField& field);
void move_iso(Viewer& viewer, ViewField& field, double steps);
// 'l': the legend on or off (with region colours there is none: false, nothing changes). Finds the
// font (find_font_file) the first time; throws std::runtime_error if there is none.
bool toggle_legend(Viewer& viewer, ViewField& field);
// The picture as shown: the scene, beside the legend (field, unit, ticks, range, map, the isovalue
// marked) when it is on.
Framebuffer presented(const Viewer& viewer, const ViewField& field);
// "temperature 53.2 °C at (x, y, z), tet 12, region 3" for pixel (x, y): the tet pick() shows there,
// the point its front face shows at the pixel's centre (pixel_point_in_tet; with --shrink the true
// point of the tet that the shrunk tet's pixel shows, as foxi probe finds it) and the field's value
// there (field_value_in_tet); "background" where no tet shows. `digits`: significant digits.
std::string value_under(const Viewer& viewer, const ViewField& field, int x, int y, int digits = 4);
// The field, map and range for the status line ("" with region colours), and what is composited.
std::string field_status(const ViewField& field);

// Hands the view what field.xray, iso_translucent and volume ask for (translucent regions and
// isosurfaces together, or the volume, or opaque tets) and restarts it. Translucent isosurfaces and
// the volume need a field: with region colours they are turned off. Ends the opaque isosurface.
void apply_composite(Viewer& viewer, ViewField& field);
// 'x', 't', 'v': x-ray, translucent isosurfaces, volume on or off (x-ray and isosurfaces together,
// the volume alone); false (nothing changes) for t and v with region colours.
bool toggle_xray(Viewer& viewer, ViewField& field);
bool toggle_iso_translucent(Viewer& viewer, ViewField& field);
bool toggle_volume(Viewer& viewer, ViewField& field);

// Runs a script of whitespace-separated commands on the viewer (the headless mode):
//   probe:X,Y    print "probe X,Y: " and value_under(X, Y) (9 digits)
//   field / map  the keys f and m
//   iso:V        the isosurface at V (display units) as the solid above it; iso-only:V the surface;
//                noiso whole tets again, i the key i (each restarts without drawing)
//   legend       the key l; prints "legend on, P pixels at the right" or "legend off"
//   xray / isoalpha / volume  the keys x, t and v (each restarts without drawing)
//   d            restart and draw to completion      c      restart without drawing
//   n            draw one batch                      f      finish the current draw
//   r / b        push the drawn tets as region / back up   (each restarts without drawing)
//   orbit:Y,P    orbit by yaw, pitch degrees         zoom:F  zoom by F       pan:X,Y  pan
//   s            save the picture as PREFIX-NNN.png (and with dump, PREFIX-NNN.ids: the id buffer as
//                little-endian uint32, and PREFIX-NNN.tets: the drawn tets, one a line)
// Prints one line per save ("saved NAME ...") on stdout. Throws std::invalid_argument on a bad command.
void run_script(Viewer& viewer, ViewField& field, const std::string& script, const std::string& prefix,
                bool dump);

// Saves the picture under the next free name PREFIX-NNN.png; prints "saved NAME camera ..." and
// returns the path. With dump, also writes the id buffer and the drawn tets beside it.
// With `field`, the picture as presented (the legend beside it when on).
std::filesystem::path save_next(const Viewer& viewer, const std::string& prefix, bool dump,
                                const ViewField* field = nullptr);

}  // namespace foxi::view
