#include "movie_composite.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/translucent.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "foxi/viz/volume.hpp"

namespace foxi::cli {

std::optional<Sweep> parse_opacity_sweep(const std::string& text) {
  if (text.rfind("opacity:", 0) != 0) return std::nullopt;
  const std::vector<double> v = parse_numbers(text.substr(8), "--sweep");
  if (v.size() != 2 || v[0] == v[1] || !(v[0] >= 0 && v[1] >= 0))
    throw UsageError(
        "--sweep opacity:a,b scales every opacity from a to b (two different factors >= 0), not '" + text +
        "'");
  Sweep s;
  s.a = v[0];
  s.b = v[1];
  return s;
}

void check_composite_movie(const CompositeOptions& composite, const std::optional<Sweep>& opacity_sweep,
                           const Sweep& sweep, const FieldOptions& field, const IsoOptions& iso,
                           double shrink, bool rotate, bool from_to_given) {
  const bool any = composite.translucent() || composite.volume_on();
  if (opacity_sweep && !any)
    throw UsageError(
        "--sweep opacity:a,b scales the opacities of --region-opacity, --iso-opacity or --volume's "
        "--opacity-curve: give one of them");
  if (!any) return;
  if (sweep.kind != Sweep::Kind::none)
    throw UsageError(
        "--region-opacity, --iso-opacity and --volume movies turn the camera (--mode rotate), grow and "
        "shrink the far part (--mode backforth) or sweep the opacities (--sweep opacity:a,b), not "
        "--sweep iso, threshold or steps");
  check_composite_options(composite, field, iso, shrink);
  if (rotate && from_to_given)
    throw UsageError(
        "a translucent or volume rotating movie draws the whole picture: leave out --from and --to");
}

CompositeMovieStats run_composite_movie(
    const CompositeMovieInputs& in,
    const std::function<void(const Framebuffer&, const FieldPicture&)>& frame) {
  CompositeMovieStats st;
  const bool volume = in.options.volume_on();
  // The isosurfaces (translucent, with --iso): resolved once, as foxi render does.
  IsoPicture iso;
  FieldPicture legend = in.field;
  if (!volume && in.iso_options.any()) {
    iso = resolve_iso(in.iso_options, in.mesh, in.field, in.subset);
    legend.legend.marks = iso.iso_si;
  }
  std::vector<double> corner;
  if (volume) corner = tet_corner_values(in.mesh, in.field.choice, in.field.step);
  auto emit = [&](const Framebuffer& fb) {
    frame(fb, legend);
    ++st.frames;
  };
  // One whole frame, as foxi render draws it.
  auto draw = [&](const Camera& camera, double scale, Framebuffer& fb) {
    if (volume) {
      const VolumeParams vp = volume_params(in.options, in.mesh, in.field, in.subset, scale);
      const VolumeReport r = draw_volume_picture(in.mesh, in.table, camera, fb, in.subset, corner, vp);
      st.exact = st.exact && r.exact_order;
      st.composited += r.tets;
      st.fragments += r.samples;
    } else {
      const TranslucentParams tp = translucent_params(in.options, in.mesh, in.render, iso, scale);
      const TranslucentReport r = draw_translucent_picture(in.mesh, in.table, camera, fb, in.subset, tp);
      st.exact = st.exact && r.exact_order;
      st.composited += r.tets_ordered;
      st.fragments += r.fragments;
    }
  };
  const MovieParams& mp = in.movie;
  if (in.opacity_sweep) {
    for (int k = 0; k < mp.frames; ++k) {
      const double s = sweep_value(*in.opacity_sweep, k, mp.frames);
      st.scales.push_back(s);
      Framebuffer fb(in.width, in.height);
      draw(in.camera, s, fb);
      emit(fb);
    }
    return st;
  }
  // Turning and back-and-forth: the library's movie (viz/movie.hpp), from the same parameters.
  CompositeMovieParams cp;
  cp.movie = mp;
  if (volume) {
    cp.volume = volume_params(in.options, in.mesh, in.field, in.subset);
    cp.corner = corner;
  } else {
    cp.translucent = translucent_params(in.options, in.mesh, in.render, iso);
  }
  try {
    static_cast<foxi::CompositeMovieStats&>(st) =
        make_composite_movie(in.mesh, in.table, in.camera, in.width, in.height, in.subset, cp,
                             [&](const Framebuffer& fb) { frame(fb, legend); });
  } catch (const UncertifiedMeshError&) {  // back-and-forth only, before any frame
    throw InputError(in.path +
                     " fails the Delaunay certificate: it has no visibility order to grow the far part of "
                     "(--mode rotate and --sweep opacity composite it without one, as foxi render does)");
  }
  return st;
}

void print_composite_movie(const CompositeMovieStats& st, const CompositeMovieInputs& in) {
  const bool volume = in.options.volume_on();
  std::printf("%s", volume ? "volume      " : "translucent ");
  if (in.opacity_sweep) {
    std::printf("every opacity scaled by s = %g to %g over %zu frames (", in.opacity_sweep->a,
                in.opacity_sweep->b, st.frames);
    for (std::size_t i = 0; i < st.scales.size(); ++i) {
      if (st.scales.size() > 12 && i == 3) {
        std::printf(", ...");
        i = st.scales.size() - 3;
      }
      std::printf("%s%g", i ? ", " : "", st.scales[i]);
    }
    std::printf("); ");
  }
  std::printf(
      "%zu tets composited%s, %zu %s\n", st.composited,
      st.recomposited > 0
          ? (" (" + std::to_string(st.recomposited) + " of them again to go back: exact undraw)").c_str()
          : "",
      st.fragments, volume ? "pixel segments integrated" : "fragments blended");
  if (st.exact)
    std::printf(
        "composited back to front in the power order (exact for this Delaunay mesh) in every frame\n");
  else
    std::printf("%s\n",
                volume ? "composited in MPVO order, NOT exact (no visibility order without the certificate)"
                       : "composited by sorting each pixel's fragments by depth (no exact order without "
                         "the certificate)");
}

}  // namespace foxi::cli
