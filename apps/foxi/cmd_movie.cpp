// foxi movie MESH: the painter's movies (seed paper, section 6.1): back-and-forth (draw back to
// front, undraw front to back) or a rotating view, as numbered PNG frames, an animated PNG, a GIF,
// or an MP4 (through the ffmpeg program, when it is installed).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "cli.hpp"
#include "composite_options.hpp"
#include "exit_codes.hpp"
#include "field_options.hpp"
#include "iso_options.hpp"
#include "movie_composite.hpp"
#include "movie_sweep.hpp"
#include "mesh_input.hpp"
#include "foxi/model/cleanup.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/animation.hpp"
#include "foxi/viz/movie.hpp"
#include "foxi/viz/picture.hpp"
#include "foxi/viz/png.hpp"
#include "foxi/viz/spheres.hpp"
#include "render_options.hpp"
#include "signals.hpp"

namespace foxi::cli {

namespace {

const std::string kMovieUsage =
    std::string(
        "foxi movie MESH [camera and picture options] [--mode backforth|rotate] [--frames N]\n"
        "                [--cycles C] [--from P%] [--to P%] [--turn deg] [--fps F]\n"
        "                [--field NAME[:C] [--graded] [--cmap M] [--range a,b] [--log] [--units U] [--step "
        "k]\n"
        "                [--legend on|off] [--threshold a,b] [--clip px,py,pz,nx,ny,nz]\n"
        "                [--sweep iso:a,b [--iso-only] | --sweep threshold:a,b | --sweep steps [--iso "
        "v,...]]]\n"
        "                [--region-opacity REGION=a,... [--iso v,... --iso-opacity a] | --volume NAME[:C]\n"
        "                --opacity-curve v0:a0,... [--opacity-length L]] [--sweep opacity:a,b]\n"
        "                [--deform NAME:SCALE] -o OUT.gif|OUT.apng|OUT.mp4|DIR/frame_%04d.png\n"
        "  A movie of the painter. backforth (the default): the tets drawn back to front in the\n"
        "  visibility order from --from to --to percent of the order (default 0% to 100%), then\n"
        "  undrawn front to back (the seed paper's undraw: back faces repainted as the neighbour's\n"
        "  front face, or restored from saved pixels), N frames per cycle, looping seamlessly.\n"
        "  rotate: the camera turned --turn degrees (default 360) about its up axis through --at over\n"
        "  N frames, each frame the first --to percent of its own order.\n"
        "  --sweep (in place of --mode) a field movie, each frame the picture foxi render draws with the\n"
        "  same options and the frame's value, in one colour range (--range, or the field's own range):\n"
        "    iso:a,b        the isosurface at v_k = a + (b - a) k / (N - 1), k = 0..N-1 (display units;\n"
        "                   N = --frames, default 48), as foxi render --iso v_k [--iso-only] draws it: only\n"
        "                   the tets v_k crosses (or reaches, for the solid) are ordered and drawn, found\n"
        "                   by an interval tree built once, so a frame costs what its isosurface holds\n"
        "    threshold:a,b  a growing threshold: frame k the tets with values in [a, v_k]\n"
        "                   (foxi render --threshold a,v_k; with --slice, the plane's section through it)\n"
        "    steps          one frame per step of the field (a transient's .pvd, a multi-step .vtu or\n"
        "                   .msh), as foxi render --step k; the range is the union over all steps unless\n"
        "                   --range is given, so colours compare across frames; --iso draws each step's\n"
        "                   isosurfaces\n"
        "  Each steps, iso and threshold frame says its value at the top left: \"t = 12.5 s\" (the step's\n"
        "  time as the file gives it; \"step k of N\" when it gives none), \"iso 32 °C\", \"threshold 30\n"
        "  to 50 °C\"; an opacity frame has no caption, so that it equals foxi render's picture.\n"
        "  --threshold and --clip select tets in every movie; --iso and --slice only with --sweep.\n"
        "  Translucent (--region-opacity, --iso-opacity) and volume (--volume) movies: each frame\n"
        "  composited exactly as foxi render composites it (options below). rotate: foxi render's\n"
        "  picture with the turned camera (not with --from, --to). backforth: the far part of the\n"
        "  power order of the composited tets growing and shrinking; compositing cannot be taken back,\n"
        "  so a shrinking frame composites the remaining far part again from the back (exactly the\n"
        "  picture of that far part drawn afresh; needs the Delaunay certificate). In place of --mode:\n"
        "    opacity:a,b    frame k with every opacity given (--region-opacity's, --iso-opacity, the\n"
        "                   opacity curve's) multiplied by s_k = a + (b - a) k / (N - 1): foxi render\n"
        "                   with those opacities (each must stay <= 1, the curve's < 1)\n") +
    kPictureOptionsHelp + kFieldOptionsHelp + kIsoOptionsHelp + kDeformOptionHelp + kCompositeOptionsHelp +
    "  (--size defaults to 640x480; with --field the colour range is the same in every frame)\n"
    "  --frames N      frames per cycle (default 48), --cycles C cycles (default 1)\n"
    "  --fps F         frames per second of the animated file (default 12)\n"
    "  -o              .gif (giflib, 256 colours per frame), .apng (animated PNG), .mp4 (needs the\n"
    "                  ffmpeg program), or a name with a printf number, e.g. out/frame_%04d.png:\n"
    "                  numbered PNG frames (the folder is created)\n"
    "  Meshes that fail the Delaunay certificate have no visibility order: backforth and rotate movies\n"
    "  of opaque tets refuse them (exit status 3); a --sweep draws each frame with the depth buffer, and\n"
    "  a translucent or volume movie composites each frame as foxi render does without the certificate\n"
    "  (fragments sorted per pixel, or MPVO order: said, not exact; no backforth). Unusable meshes (see\n"
    "  foxi info) are refused; inverted tets are re-oriented (a note says so).";

double percent(const std::string& s, const char* what, double fallback) {
  if (s.empty()) return fallback;
  std::string v = s;
  if (v.back() == '%') v.pop_back();
  char* end = nullptr;
  const double p = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != 0 || !(p >= 0 && p <= 100))
    throw UsageError(std::string(what) + " takes a percentage 0..100, e.g. 40%");
  return p / 100;
}

long whole(const std::string& s, const char* what, long fallback, long lo, long hi) {
  if (s.empty()) return fallback;
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (*end != 0 || v < lo || v > hi)
    throw UsageError(std::string(what) + " takes a whole number in " + std::to_string(lo) + ".." +
                     std::to_string(hi));
  return v;
}

// Looked up in PATH here rather than by a shell: a child process foxi does not track could outlive a stop.
bool have_ffmpeg() {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  std::size_t at = 0;
  while (at <= dirs.size()) {
    const std::size_t colon = std::min(dirs.find(':', at), dirs.size());
    const std::string dir = dirs.substr(at, colon - at);
    const std::string exe = (dir.empty() ? std::string(".") : dir) + "/ffmpeg";
    if (::access(exe.c_str(), X_OK) == 0 && !std::filesystem::is_directory(exe)) return true;
    at = colon + 1;
  }
  return false;
}

}  // namespace

int cmd_movie(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kMovieUsage.c_str());
    return kExitOk;
  }
  // First: --volume NAME is the field to draw (the field options apply to it).
  const CompositeOptions composite = take_composite_options(args);
  const bool compositing = composite.translucent() || composite.volume_on();
  const std::string sweep_s = args.option("--sweep");
  const std::optional<Sweep> opacity_sweep = parse_opacity_sweep(sweep_s);
  const Sweep sweep = opacity_sweep ? Sweep{} : parse_sweep(sweep_s);
  const bool sweeping = sweep.kind != Sweep::Kind::none || opacity_sweep;
  if (sweeping && args.has_option("--mode"))
    throw UsageError("--sweep is a kind of movie in place of --mode: give one");
  // --iso-only belongs to the swept isovalue here, which take_iso_options does not see.
  const bool sweep_iso_only = sweep.kind == Sweep::Kind::iso && args.flag("--iso-only");
  const std::string mode = sweeping ? std::string("sweep") : args.option("--mode", "backforth");
  const std::string frames_s = args.option("--frames"), cycles_s = args.option("--cycles");
  const std::string from_s = args.option("--from"), to_s = args.option("--to"),
                    turn_s = args.option("--turn");
  const std::string fps_s = args.option("--fps", "12");
  std::string out = args.option("-o");
  if (out.empty()) out = args.option("--output");
  PictureOptions options = take_picture_options(args, "640x480");
  FieldOptions field_options = take_field_options(args);
  field_options.corner_range = composite.volume_on() || composite.has_iso_opacity;
  if (field_options.markers)
    throw UsageError("--markers marks a picture: foxi render takes it, foxi movie does not");
  const IsoOptions iso_options = take_iso_options(args, field_options);
  const std::optional<DeformOption> deform = take_deform_option(args);
  const std::string path = args.positional(1, 1, kMovieUsage)[0];
  if (out.empty()) throw UsageError("give the output with -o OUT.gif|OUT.apng|OUT.mp4|DIR/frame_%04d.png");
  if (mode != "backforth" && mode != "rotate" && mode != "sweep")
    throw UsageError("--mode takes backforth or rotate");
  if (compositing || opacity_sweep)
    check_composite_movie(composite, opacity_sweep, sweep, field_options, iso_options, options.params.shrink,
                          mode == "rotate", !from_s.empty() || !to_s.empty());
  else
    check_sweep_options(sweep, field_options, iso_options);
  if (sweeping && !(cycles_s.empty() && from_s.empty() && to_s.empty() && turn_s.empty()))
    throw UsageError("--cycles, --from, --to and --turn belong to --mode backforth|rotate, not to --sweep");
  if (sweep.kind == Sweep::Kind::steps && !frames_s.empty())
    throw UsageError("--sweep steps draws one frame per step of the field: leave out --frames");
  MovieParams mp;
  mp.rotate = mode == "rotate";
  mp.frames = int(whole(frames_s, "--frames", 48, 2, 100000));
  mp.cycles = int(whole(cycles_s, "--cycles", 1, 1, 1000));
  mp.from = percent(from_s, "--from", 0);
  mp.to = percent(to_s, "--to", 1);
  if (mp.from > mp.to) throw UsageError("--from must not exceed --to");
  if (!turn_s.empty()) {
    char* end = nullptr;
    mp.turn_deg = std::strtod(turn_s.c_str(), &end);
    if (*end != 0 || !std::isfinite(mp.turn_deg)) throw UsageError("--turn takes degrees");
  }
  char* fps_end = nullptr;
  const double fps = std::strtod(fps_s.c_str(), &fps_end);
  if (*fps_end != 0 || !(fps > 0 && fps <= 100)) throw UsageError("--fps takes a rate in (0, 100]");

  enum class Kind { frames, gif, apng, mp4 } kind;
  const std::string ext = std::filesystem::path(out).extension().string();
  if (out.find('%') != std::string::npos) {
    if (!frame_pattern(out))
      throw UsageError("-o " + out + ": a frame name needs one %d or %0Nd and no other %");
    kind = Kind::frames;
  } else if (ext == ".gif") {
    kind = Kind::gif;
    // A GIF frame's delay is 16 bits of hundredths of a second (at most 655.35 s): slower would be
    // clamped in silence.
    if (fps < 100.0 / 65535)
      throw UsageError("--fps " + fps_s +
                       ": a GIF shows a frame at most 655.35 s (--fps 0.0016 or more; an .apng "
                       "holds slower ones)");
  } else if (ext == ".apng") {
    kind = Kind::apng;
  } else if (ext == ".mp4") {
    kind = Kind::mp4;
    if (!have_ffmpeg())
      throw UsageError(
          "-o " + out +
          ": MP4 needs the ffmpeg program, which is not installed (write .gif, .apng or frames)");
  } else {
    throw UsageError("-o " + out +
                     ": give .gif, .apng, .mp4 or a numbered frame name like dir/frame_%04d.png");
  }
  if (kind != Kind::frames) check_output_path(out);  // before the work (frames: once their folder is made)

  Mesh read = read_usable_mesh(path, "movie");
  const double moved = deform ? apply_deform(read, *deform, path, "movie") : 0;
  const Mesh& mesh = read;
  Picture picture = resolve_picture(options, mesh);
  // Colour by a field: one paint (one range) for the whole movie; the legend drawn beside each frame
  // (a sweep's legend marks the frame's isovalue, so it is drawn per frame).
  FieldPicture field;
  std::unique_ptr<TextRenderer> text;
  int panel = 0;
  std::size_t step_count = 1;
  if (!field_options.spec.empty()) {
    if (sweep.kind == Sweep::Kind::steps) {
      const SweepRange r = fixed_step_range(field_options, mesh, picture.subset, path);
      step_count = r.steps;
      field_options.has_si_range = true;
      field_options.si_range[0] = r.lo;
      field_options.si_range[1] = r.hi;
      field_options.step = 0;
    }
    field = resolve_field(field_options, mesh, picture.subset, path);
    if (sweep.kind == Sweep::Kind::steps && step_count < 2)
      throw UsageError(path + ": field '" + field.choice.field->name +
                       "' has one step: --sweep steps needs several");
    options.params.field = field.paint;
    if (field_options.legend) {
      text = std::make_unique<TextRenderer>(find_font_file());
      panel = legend_panel(*text, field, options.width, options.height);
      options.width -= panel;
      picture = resolve_picture(options, mesh);
    }
  }
  // --threshold and --clip narrow the tets of every kind of movie.
  if (!sweeping && !compositing && iso_options.any()) {
    IsoPicture sel = resolve_iso(iso_options, mesh, field, picture.subset);
    if (sel.empty) throw UsageError("--threshold and --clip select no tets of " + path);
    picture.subset = std::move(sel.subset);
  }
  mp.render = options.params;
  const SphereTable table = compute_spheres(mesh);

  AnimationParams ap;
  ap.width = options.width + panel;
  ap.height = options.height;
  ap.fps = fps;
  std::unique_ptr<AnimationWriter> writer;
  // Numbered frames (and the mp4's frames for ffmpeg) are written as DurableFile temporaries and
  // committed together at the end: a stopped or failed movie leaves no frame behind.
  std::vector<DurableFile> frames;
  std::filesystem::path frame_dir;  // mp4: the PNG frames for ffmpeg, a tracked temporary folder
  std::string pattern = out;
  if (kind == Kind::gif) writer = open_gif(out, ap);
  if (kind == Kind::apng) writer = open_apng(out, ap);
  if (kind == Kind::mp4) {
    frame_dir = std::filesystem::path(out + ".foxi-tmp-" + std::to_string(::getpid()) + "-frames");
    cleanup::with_lock([&] {
      cleanup::track(frame_dir, true);
      std::filesystem::create_directories(frame_dir);
    });
    pattern = (frame_dir / "frame_%06d.png").string();
  }
  std::filesystem::path created;  // the first folder of the frames' path that this run created
  if (kind == Kind::frames) {
    const std::filesystem::path parent = std::filesystem::path(frame_name(pattern, 0)).parent_path();
    if (!parent.empty()) {
      for (std::filesystem::path p = parent; !p.empty() && !std::filesystem::exists(p); p = p.parent_path()) {
        created = p;
        if (p == p.parent_path()) break;
      }
      cleanup::with_lock([&] {
        if (!created.empty()) cleanup::track(created, true);
        std::filesystem::create_directories(parent);
      });
    }
    check_output_path(frame_name(pattern, 0));
    // Once for the folder rather than once per frame (each a reading of the whole folder).
    remove_stale_temporaries_in(std::filesystem::path(frame_name(pattern, 0)).parent_path().empty()
                                    ? std::filesystem::path(".")
                                    : std::filesystem::path(frame_name(pattern, 0)).parent_path());
  }
  struct Forget {
    std::filesystem::path dir;
    bool remove;
    ~Forget() {
      std::error_code ec;
      if (!dir.empty() && remove) std::filesystem::remove_all(dir, ec);
      if (!dir.empty()) cleanup::untrack(dir);
    }
  } forget_frames{frame_dir, true}, forget_created{created, true};

  std::size_t index = 0;
  // One frame out: the scene with its caption (a sweep's time or value) at the top left, beside the
  // legend of `legend_of` when there is one.
  auto emit = [&](const Framebuffer& scene, const FieldPicture& legend_of, const std::string& caption) {
    Framebuffer captioned;
    if (!caption.empty()) {
      if (!text) text = std::make_unique<TextRenderer>(find_font_file());
      captioned = scene;
      draw_caption(captioned, *text, caption);
    }
    const Framebuffer& shown = caption.empty() ? scene : captioned;
    if (writer) {
      writer->add(panel > 0 ? with_legend(shown, *text, legend_of, panel) : shown);
    } else {
      frames.emplace_back(frame_name(pattern, index), false);
      write_png(frames.back(), panel > 0 ? with_legend(shown, *text, legend_of, panel) : shown);
    }
    ++index;
  };
  const auto t0 = std::chrono::steady_clock::now();
  MovieStats stats;
  SweepStats sweep_stats;
  const CompositeMovieInputs composite_in{mesh,
                                          table,
                                          picture.camera,
                                          options.width,
                                          options.height,
                                          picture.subset,
                                          composite,
                                          options.params,
                                          field,
                                          iso_options,
                                          mp,
                                          opacity_sweep,
                                          path};
  CompositeMovieStats composite_stats;
  if (compositing) {
    // Uncaptioned: each frame is foxi render's picture (the report lists the opacity factors).
    composite_stats = run_composite_movie(
        composite_in,
        [&](const Framebuffer& scene, const FieldPicture& legend_of) { emit(scene, legend_of, {}); });
    stats.frames = composite_stats.frames;
  } else if (sweeping) {
    SweepInputs in{mesh,           table,          picture.camera, options.width, options.height,
                   options.params, picture.subset, field_options,  field,         iso_options,
                   sweep,          sweep_iso_only, mp.frames,      step_count,    path};
    sweep_stats = run_sweep(in, emit);
    stats.frames = sweep_stats.frames;
  } else {
    try {
      stats = make_movie(mesh, table, picture.camera, options.width, options.height, picture.subset, mp,
                         [&](const Framebuffer& scene) { emit(scene, field, std::string()); });
    } catch (const UncertifiedMeshError&) {  // thrown before the first frame: nothing written
      throw InputError(
          path + (deform ? " deformed by " + deform->name : std::string()) +
          " fails the Delaunay certificate: it has no visibility order to make a back-and-forth or "
          "rotating movie with (foxi render --zbuffer draws it; a --sweep draws each frame with the "
          "depth buffer)");
    }
  }
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (writer) writer->finish();
  if (!writer) commit_together(frames);                     // numbered frames, or ffmpeg's input
  if (kind == Kind::frames) forget_created.remove = false;  // the frames are in it now
  if (kind == Kind::mp4) {
    DurableFile video(out);
    const std::vector<std::string> ffmpeg = {"ffmpeg",
                                             "-y",
                                             "-loglevel",
                                             "error",
                                             "-framerate",
                                             std::to_string(fps),
                                             "-i",
                                             (frame_dir / "frame_%06d.png").string(),
                                             "-vf",
                                             "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                             "-pix_fmt",
                                             "yuv420p",
                                             "-c:v",
                                             "libx264",
                                             "-f",
                                             "mp4",
                                             video.temp().string()};
    if (run_program(ffmpeg) != 0) throw std::runtime_error(out + ": ffmpeg failed to encode the frames");
    video.commit();
  }
  std::printf("mesh        %s: %zu tets, %zu shown\n", path.c_str(), mesh.tet_count(),
              picture.subset.empty() ? mesh.tet_count() : picture.subset.size());
  if (deform)
    std::printf("deformed    by %s x %g: nodes moved up to %g\n", deform->name.c_str(), deform->scale, moved);
  std::printf("movie       %s, %zu frames of %dx%d, %.1f ms per frame (frames written included)\n",
              mode.c_str(), stats.frames, ap.width, options.height,
              ms / double(std::max<std::size_t>(1, stats.frames)));
  if (compositing) {
    print_composite_movie(composite_stats, composite_in);
  } else if (sweeping) {
    print_sweep(sweep_stats, sweep, field);
  } else {
    std::printf("painter     %zu tets drawn, %zu undrawn, undraw memory at most %.1f MB\n", stats.tets_drawn,
                stats.tets_undrawn, double(stats.max_undo_bytes) / 1e6);
  }
  if (field.paint) {
    const DisplayUnit& u = field.legend.unit;
    std::printf("field       %s, %s, %s, %s%s, colours %.6g to %.6g%s%s in every frame%s\n",
                field.legend.title.c_str(),
                sweep.kind == Sweep::Kind::steps ? ("steps 0 to " + std::to_string(step_count - 1)).c_str()
                                                 : ("step " + std::to_string(field.step)).c_str(),
                composite.volume_on()  ? "linear in each tet (corner values)"
                : compositing          ? "on the isosurfaces"
                : field_options.graded ? "graded facets"
                                       : "flat per tet",
                color_map_name(field.legend.scale.map), field.legend.scale.log ? " log" : "",
                u.to_display(field.legend.scale.lo), u.to_display(field.legend.scale.hi),
                u.symbol.empty() ? "" : " ", u.symbol.c_str(), panel > 0 ? ", legend at the right" : "");
    if (compositing && field.no_value > 0)
      std::printf("warning     %zu corner values are NaN or infinite: %s\n", field.no_value,
                  composite.volume_on() ? "the tets with one are left out (transparent)"
                                        : "no isosurface crosses the tets with one");
  }
  std::printf("wrote       %s\n", out.c_str());
  return kExitOk;
}

}  // namespace foxi::cli
