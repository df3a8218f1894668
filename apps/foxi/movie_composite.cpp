#include "movie_composite.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "foxi/model/delaunay.hpp"
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

namespace {

// The first round(n f) of n.
std::size_t prefix(std::size_t n, double fraction) {
  return std::min(n, std::size_t(std::llround(std::clamp(fraction, 0.0, 1.0) * double(n))));
}

// One of the two compositing painters, for the back-and-forth movie.
struct Compositor {
  std::unique_ptr<TranslucentPainter> translucent;
  std::unique_ptr<VolumePainter> volume;
  void draw(std::span<const std::uint32_t> tets) {
    if (translucent)
      translucent->draw(tets);
    else
      volume->draw(tets);
  }
  void resolve(Framebuffer& fb) {
    if (translucent)
      translucent->resolve(fb);
    else
      volume->resolve(fb);
  }
  std::size_t fragments() const { return translucent ? translucent->fragment_count() : volume->samples(); }
};

}  // namespace

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
  if (mp.rotate) {
    for (int c = 0; c < mp.cycles; ++c)
      for (int k = 0; k < mp.frames; ++k) {
        Framebuffer fb(in.width, in.height);
        draw(orbit(in.camera, mp.turn_deg * k / mp.frames, 0), 1, fb);
        emit(fb);
      }
    return st;
  }
  // Back and forth: the far part of the power order of the tets that own something to draw.
  if (!delaunay_certificate(in.mesh).delaunay)
    throw InputError(in.path +
                     " fails the Delaunay certificate: it has no visibility order to grow the far part of "
                     "(--mode rotate and --sweep opacity composite it without one, as foxi render does)");
  TranslucentParams tp;
  VolumeParams vp;
  TranslucentSurfaces surfaces;
  std::span<const std::uint32_t> tets = in.subset;
  if (volume) {
    vp = volume_params(in.options, in.mesh, in.field, in.subset);
  } else {
    tp = translucent_params(in.options, in.mesh, in.render, iso);
    surfaces = translucent_surfaces(in.mesh, in.subset, tp);
    tets = surfaces.tets;
  }
  std::vector<std::uint32_t> order;
  if (volume || !tets.empty()) order = visibility_order(in.mesh, in.table, view_of(in.camera), tets);
  const std::span<const std::uint32_t> all(order);
  auto fresh = [&] {
    Compositor c;
    if (volume)
      c.volume = std::make_unique<VolumePainter>(in.mesh, in.camera, in.width, in.height, corner, vp);
    else
      c.translucent =
          std::make_unique<TranslucentPainter>(in.mesh, in.camera, in.width, in.height, surfaces, tp);
    return c;
  };
  Compositor painter = fresh();
  std::size_t fragments_before = 0;  // of the painters replaced
  std::size_t have = prefix(order.size(), mp.from);
  painter.draw(all.first(have));
  st.composited += have;
  const int half = mp.frames / 2;
  Framebuffer fb(in.width, in.height);
  for (int c = 0; c < mp.cycles; ++c)
    for (int k = 0; k < mp.frames; ++k) {
      const double t = k <= half ? double(k) / half : double(mp.frames - k) / double(mp.frames - half);
      const std::size_t want = prefix(order.size(), mp.from + (mp.to - mp.from) * t);
      if (want > have) {
        painter.draw(all.subspan(have, want - have));
        st.composited += want - have;
      } else if (want < have) {
        fragments_before += painter.fragments();
        painter = fresh();
        painter.draw(all.first(want));
        st.composited += want;
        st.recomposited += want;
      }
      have = want;
      painter.resolve(fb);
      emit(fb);
    }
  st.fragments = fragments_before + painter.fragments();
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
