// foxi/viz.hpp: the visibility order of tets and the software painter (foxi::viz), in one include.
// The entry points, one a line (declared in the topic headers below, which say more):
//
//   draw_picture(mesh, table, camera, fb)     a safe picture: painter if certified, else MPVO + depth buffer
//   draw_picture(view, table, camera, image, scratch)  the same into a host's RGBA buffer with its stride
//   (picture.hpp) safe_order(mesh, table, view, subset)      the back-to-front order draw_picture uses
//   (picture.hpp) InteractiveView                            camera, regions of interest, progressive
//   draw/undraw, damage, pick (interactive_view.hpp) material_color, exploded_mesh              colours of
//   materials, parts lifted apart (palette.hpp) parse_camera_options, parse_subset, ...    the front ends'
//   picture options read from text (view_options.hpp) compute_spheres(mesh)                      per-mesh
//   precompute of the power order (spheres.hpp) visibility_order(mesh, table, view, subset) back-to-front
//   order for one view; Delaunay meshes (visibility_order.hpp) ProgressiveOrder                           the
//   same handed out batch by batch (visibility_order.hpp) mpvo_order(mesh, table, view, subset)      order of
//   a non-Delaunay mesh, cycles counted (visibility_order.hpp) count_violations(mesh, view, order)
//   face-adjacent pairs drawn in the wrong order (visibility_order.hpp) Camera, fit_camera, orbit, pan, zoom
//   the camera and its helpers (camera.hpp) view_of(camera), View                      the ordering viewpoint
//   of a camera (camera.hpp, view.hpp) TetRasterizer, RenderParams                the painter: draw, undraw,
//   changed rects (rasterizer.hpp) render_tets(mesh, camera, w, h, tets)      a fresh framebuffer with tets
//   drawn (rasterizer.hpp) Framebuffer, pack_rgba                     RGBA8 pixels, tet ids, depth
//   (framebuffer.hpp) write_png(path, fb), read_png(path)        PNG files of a framebuffer (png.hpp)
//   tets_bounds(mesh, subset, lo, hi)         bounds of a subset, to fit a camera to (camera.hpp)
//   tet_depth, count_deeper                    the painter's depth stop (depth_stop.hpp)
//   make_movie(...)                            movies of the painter: APNG, GIF (movie.hpp, animation.hpp)
//   node_corner_values, cell_corner_values    a host's own node or cell array as corner values
//   (field_paint.hpp) choose_field, tet_corner_values, FieldPaint colour by a field: flat or graded
//   (field_paint.hpp, RenderParams::field) ColorScale, color_map_entry, nice_ticks    colour maps, ranges,
//   colour-bar ticks (colormap.hpp) TextRenderer, find_font_file               text in pictures with FreeType
//   (text.hpp) draw_color_legend, legend_width            a colour-bar legend drawn into a picture
//   (legend.hpp) draw_chart, Chart, axis_ticks              line charts: series, log axes, legend (chart.hpp)
//   draw_translucent_picture, TranslucentPainter translucent regions and isosurfaces, exactly composited
//   (translucent.hpp) draw_volume_picture, VolumePainter         volume rendering by projected tetrahedra,
//   power order (volume.hpp)
#pragma once

#include "foxi/viz/animation.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/chart.hpp"
#include "foxi/viz/colormap.hpp"
#include "foxi/viz/depth_stop.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/interactive_view.hpp"
#include "foxi/viz/legend.hpp"
#include "foxi/viz/movie.hpp"
#include "foxi/viz/palette.hpp"
#include "foxi/viz/picture.hpp"
#include "foxi/viz/png.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/text.hpp"
#include "foxi/viz/translucent.hpp"
#include "foxi/viz/view.hpp"
#include "foxi/viz/view_options.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "foxi/viz/volume.hpp"
